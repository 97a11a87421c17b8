"""Actuator sizing: per drive, the peak and RMS effort, peak speed and power, and the
torque-speed envelope of a task-space motion; the motion's nearest approach to each kind of
singularity. A payload at the end effector is added to the model first (:func:`with_payload`).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..mechanism import Mechanism, from_dict
from .effector import EndEffector
from .motion import TaskMotion, solve_motion

if TYPE_CHECKING:
    from .paths import TaskPath

FloatArray = NDArray[np.float64]

_MASS_FIELDS = ("mass", "inertia", "inertia_about_com", "com", "uniform_bar", "parts")


def with_payload(mech: Mechanism, point: str, mass: float, inertia: float = 0.0, body: str | None = None) -> Mechanism:
    """The mechanism with a payload (mass kg, inertia kg m^2 about its centre) at ``point``,
    added as a part of the body carrying it (``body``: which, when several do)."""
    if not mass > 0:
        raise ValueError(f"payload mass must be > 0 kg, got {mass}")
    model = copy.deepcopy(mech.to_dict())
    carriers = [b for b, spec in model["bodies"].items() if point in spec.get("points", [])]
    if body is None:
        if not carriers:
            raise ValueError(f"no body carries point {point!r}")
        body = carriers[0]
    elif body not in carriers:
        raise ValueError(f"body {body!r} does not carry point {point!r}")
    spec = model["bodies"][body]
    if "parts" in spec:
        parts = spec["parts"]
    elif "uniform_bar" in spec:
        parts = [{"mass": spec["mass"], "uniform_bar": spec["uniform_bar"]}]
    else:
        parts = [{"mass": spec["mass"], "inertia": spec.get("inertia", spec.get("inertia_about_com")), "com": spec["com"]}]
    for k in _MASS_FIELDS:
        spec.pop(k, None)
    payload = {"mass": float(mass), "point_mass": point} if inertia == 0 else {"mass": float(mass), "inertia": float(inertia), "com": point}
    spec["parts"] = [*parts, payload]
    model["name"] = f"{model.get('name', 'mechanism')} + {mass:g} kg at {point}"
    return from_dict(model, source=f"{mech.source} (payload)")


@dataclass
class LimitCheck:
    """One motor limit against the motion's demand: ``demand`` and ``limit`` in ``unit``
    (the torque-speed check: the largest |t_m| / available torque, against 1)."""

    quantity: str
    demand: float
    limit: float
    unit: str

    @property
    def margin(self) -> float:
        """1 - demand / limit: the fraction of the limit left (negative: exceeded)."""
        return 1.0 - self.demand / self.limit

    @property
    def passed(self) -> bool:
        return self.demand <= self.limit


@dataclass
class MotorSizing:
    """A drive's motor side (N m, rad/s, W): the torque t_m and speed n qd at every sample,
    their peaks, the RMS torque, the peak power t_m n qd, the limit checks, and the motor's
    torque-speed envelope (available torque against speed) for plotting."""

    name: str
    torque: FloatArray
    speed: FloatArray
    peak_torque: float
    rms_torque: float
    peak_speed: float
    peak_power: float
    checks: list[LimitCheck]
    envelope_speed: FloatArray
    envelope_torque: FloatArray

    @property
    def passed(self) -> bool:
        """Whether every given limit holds (True when none is given)."""
        return all(c.passed for c in self.checks)


@dataclass
class DriveSizing:
    """One drive's requirements (units of its coordinate: N m and rad/s, or N and m/s; W),
    joint-side; ``motor`` the motor side when the model gives the coordinate an actuator."""

    name: str
    effort_unit: str
    speed_unit: str
    peak_effort: float
    rms_effort: float
    peak_speed: float
    peak_power: float
    envelope_speed: FloatArray
    envelope_effort: FloatArray
    motor: MotorSizing | None = None


@dataclass
class SizingReport:
    """Actuator requirements of a task-space motion; ``drives`` one :class:`DriveSizing` each.

    ``min_sigma_I``/``min_sigma_II`` (dimensionless) with the time (s) and end-effector
    position (m) where each is reached: the motion's nearest approach to each singularity.
    """

    motion: TaskMotion
    payload: float
    drives: list[DriveSizing]
    min_sigma_I: tuple[float, float, FloatArray]
    min_sigma_II: tuple[float, float, FloatArray]

    def __str__(self) -> str:
        m = self.motion
        lines = [f"sizing of {m.mech.name} on {m.label}" + (f", payload {self.payload:g} kg" if self.payload else ""),
                 f"{'drive':>10} {'peak effort':>14} {'RMS effort':>14} {'peak speed':>16} {'peak power':>11}"]
        for d in self.drives:
            lines.append(f"{d.name:>10} {d.peak_effort:>10.4g} {d.effort_unit:<3} {d.rms_effort:>10.4g} {d.effort_unit:<3} "
                         f"{d.peak_speed:>10.4g} {d.speed_unit:<5} {d.peak_power:>9.4g} W")
        for d in self.drives:
            if d.motor is None:
                continue
            mo = d.motor
            lines.append(f"{d.name:>10} motor {mo.name}: peak {mo.peak_torque:.4g} N m, RMS {mo.rms_torque:.4g} N m, "
                         f"speed {mo.peak_speed:.4g} rad/s, power {mo.peak_power:.4g} W")
            for c in mo.checks:
                lines.append(f"{'':>12}{c.quantity:<14} {c.demand:>10.4g} of {c.limit:<10.4g} {c.unit:<6} "
                             f"margin {100 * c.margin:>7.2f} %  {'pass' if c.passed else 'FAIL'}")
        for kind, (s, t, X) in (("I", self.min_sigma_I), ("II", self.min_sigma_II)):
            lines.append(f"nearest type {kind} singularity: sigma_{kind} = {s:.3g} at t = {t:.3f} s, "
                         f"end effector at ({X[0]:.4f}, {X[1]:.4f}) m")
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """Plain numbers (for JSON): per drive the peaks and RMS, and the singularity margins."""
        return {
            "model": self.motion.mech.name, "path": self.motion.label, "payload_kg": self.payload,
            "drives": [{k: getattr(d, k) for k in ("name", "effort_unit", "speed_unit", "peak_effort", "rms_effort",
                                                   "peak_speed", "peak_power")}
                       | ({} if d.motor is None else {"motor": _motor_dict(d.motor)}) for d in self.drives],
            "min_sigma_I": {"value": self.min_sigma_I[0], "t": self.min_sigma_I[1], "X": self.min_sigma_I[2].tolist()},
            "min_sigma_II": {"value": self.min_sigma_II[0], "t": self.min_sigma_II[1], "X": self.min_sigma_II[2].tolist()},
        }


def _motor_dict(mo: MotorSizing) -> dict[str, Any]:
    return {"name": mo.name, "peak_torque": mo.peak_torque, "rms_torque": mo.rms_torque, "peak_speed": mo.peak_speed,
            "peak_power": mo.peak_power, "passed": mo.passed,
            "checks": [{"quantity": c.quantity, "demand": c.demand, "limit": c.limit, "unit": c.unit,
                        "margin": c.margin, "passed": c.passed} for c in mo.checks]}


def motor_sizing(mech: Mechanism, k: int, t: FloatArray, qd: FloatArray, t_m: FloatArray) -> MotorSizing | None:
    """The motor side of actuator ``k``'s drive along samples at times ``t`` (s) with the
    actuators' rates ``qd`` and motor torques ``t_m`` (N, m; or N, n_a with the pair
    actuators: :meth:`Mechanism.motor_torques`, a solved motion's ``tau_motor``); None
    without a motor."""
    act = mech.actuators[k]
    if act is None:
        return None
    t_m = np.asarray(t_m, dtype=float)[:, k]
    w = act["gear_ratio"] * qd[:, k]
    peak_t, rms_t, peak_w = float(np.abs(t_m).max()), _rms(t, t_m), float(np.abs(w).max())
    checks = []
    for quantity, demand, limit, unit in (("peak torque", peak_t, act["peak_torque"], "N m"),
                                          ("RMS torque", rms_t, act["continuous_torque"], "N m"),
                                          ("speed", peak_w, act["max_speed"], "rad/s")):
        if limit is not None:
            checks.append(LimitCheck(quantity, demand, float(limit), unit))
    top = max(peak_w, act["max_speed"] or 0.0, float(act["envelope"][-1, 0]) if len(act["envelope"]) else 0.0)
    env_w = np.linspace(0.0, 1.05 * top, 256)
    env_t = mech.available_torque(k, env_w)
    available = mech.available_torque(k, w)
    if len(act["envelope"]) and available is not None:
        with np.errstate(divide="ignore"):
            ratio = np.where(available > 0, np.abs(t_m) / np.where(available > 0, available, 1.0),
                             np.where(np.abs(t_m) > 0, np.inf, 0.0))
        checks.append(LimitCheck("torque-speed", float(ratio.max()), 1.0, "of env"))
    return MotorSizing(act["name"], t_m, w, peak_t, rms_t, peak_w, float(np.abs(t_m * w).max()), checks,
                       env_w, np.zeros_like(env_w) if env_t is None else env_t)


def envelope(speed: FloatArray, effort: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Torque-speed envelope: for each speed v, the largest |effort| needed at a speed >= v
    (a staircase falling with speed); a motor whose continuous curve lies above it can drive
    the motion. Returns (speeds ascending, efforts), both >= 0."""
    v, e = np.abs(speed), np.abs(effort)
    order = np.argsort(-v)
    env = np.maximum.accumulate(e[order])
    return v[order][::-1], env[::-1]


def _rms(t: FloatArray, y: FloatArray) -> float:
    if len(t) < 2:
        return float(np.abs(y).max()) if len(y) else 0.0
    y2 = y**2
    integral = float(np.sum(0.5 * (y2[1:] + y2[:-1]) * np.diff(t)))  # trapezoidal rule
    return float(np.sqrt(integral / (t[-1] - t[0])))


def distributed_efforts(mech: Mechanism, motion: TaskMotion, distribution: str = "min_norm",
                        preload: list[float] | None = None) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Every actuator's effort (N, n_a) along a motion of a redundantly actuated mechanism,
    shared by ``distribution`` (:meth:`Mechanism.distribute_efforts`), each actuator's rate
    (N, n_a): B^T qd (rad/s or m/s on its pair), and its motor torque (N, n_a)."""
    efforts, rates, torques = [], [], []
    for q, qd, qdd in zip(motion.q, motion.qd, motion.qdd):
        out = mech.distribute_efforts(q, qd, qdd, distribution, preload)  # type: ignore[arg-type]
        efforts.append(out["efforts"])
        rates.append(out["B"].T @ qd)
        torques.append(out["motor_torques"])
    return np.array(efforts), np.array(rates), np.array(torques)


def size(motion: TaskMotion | EndEffector, path: TaskPath | None = None, *, payload: float = 0.0,
         distribution: str = "min_norm", preload: list[float] | None = None, **solve_options: Any) -> SizingReport:
    """Actuator sizing report of a task-space motion.

    Parameters
    ----------
    motion : TaskMotion or EndEffector
        A solved motion; or an end effector, with ``path``, to solve (with ``payload``).
    path : TaskPath
        The motion to size when ``motion`` is an end effector.
    payload : float
        Mass (kg) added at the end-effector point first (:func:`with_payload`); only with an
        end effector and a path (a solved motion already has its model).
    distribution, preload
        With more actuators than coordinates (``actuators: [{pair: ...}]``), how their
        efforts are shared: ``"min_norm"``, ``"min_max"`` or ``"preload"`` with ``preload``
        (:meth:`Mechanism.distribute_efforts`); every actuator is then sized.
    solve_options
        Passed to :func:`solve_motion` (``dt``, ``n``, ``q_start``, ``singular_tol``).
    """
    if isinstance(motion, EndEffector):
        if path is None:
            raise ValueError("size(effector, path): the path is missing")
        ee = motion
        if payload:
            mech = with_payload(ee.mech, ee.point, payload, body=ee.body)
            ee = EndEffector(mech, ee.point, ee.body)
        motion = solve_motion(ee, path, **solve_options)
    elif payload or path is not None:
        raise ValueError("a solved motion already has its model and path: pass size(effector, path, payload=...)")
    mech = motion.mech
    names = mech.actuator_names
    m = len(mech.coordinate_names)
    if len(names) > m:
        efforts, rates, torques = distributed_efforts(mech, motion, distribution, preload)
    else:
        efforts, rates = motion.tau, motion.qd
        torques = (np.asarray(mech.motor_torques(motion.q, motion.qd, motion.qdd, motion.tau, allow_singular=True))
                   if motion.tau_motor is None else motion.tau_motor)
    kinds = mech.actuator_kinds
    drives = []
    for k, name in enumerate(names):
        tau, qd = efforts[:, k], rates[:, k]
        ev, ee_ = envelope(qd, tau)
        angle = kinds[k] == "angle"
        drives.append(DriveSizing(name, "N m" if angle else "N", "rad/s" if angle else "m/s", float(np.abs(tau).max()),
                                  _rms(motion.t, tau), float(np.abs(qd).max()), float(np.abs(tau * qd).max()), ev, ee_,
                                  motor_sizing(mech, k, motion.t, rates, torques)))
    iI, iII = int(np.argmin(motion.sigma_I)), int(np.argmin(motion.sigma_II))
    return SizingReport(motion, float(payload), drives,
                        (float(motion.sigma_I[iI]), float(motion.t[iI]), motion.X[iI]),
                        (float(motion.sigma_II[iII]), float(motion.t[iII]), motion.X[iII]))
