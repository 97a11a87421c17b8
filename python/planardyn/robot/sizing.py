"""Actuator sizing: per drive, the peak and RMS effort, peak speed and power, and the
torque-speed envelope of a task-space motion; the motion's nearest approach to each kind of
singularity. A payload at the end effector is added to the model first (:func:`with_payload`).
The peaks hold between the samples: the sampling must resolve the path, and the motion is
solved again finer around every sampled peak (planardyn.robot.sampling); the RMS values are
integrals over the samples by Simpson's rule.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._core import modes as native_modes
from ..mechanism import Mechanism, from_dict
from ..notebook import Summarized
from .effector import EndEffector
from .motion import TaskMotion, _sample_times, solve_motion
from .paths import TaskPath
from .sampling import FINE, SizingError, check_path, check_rms, check_samples, peak_windows

FloatArray = NDArray[np.float64]

#: How redundant actuators' efforts are shared (Mechanism.distribute_efforts).
DISTRIBUTIONS = ("min_norm", "min_max", "preload")

#: The most samples a sizing takes (n, or the duration over dt): 1e7 samples of a 3-DOF
#: motion hold about 3 GB.
MAX_SAMPLES = 10_000_000

#: The largest payload mass (kg) and inertia (kg m^2): a model file's bound on its numbers.
MAX_MASS = 1e30

_MASS_FIELDS = ("mass", "inertia", "inertia_about_com", "com", "uniform_bar", "parts")


def with_payload(mech: Mechanism, point: str, mass: float, inertia: float = 0.0, body: str | None = None) -> Mechanism:
    """The mechanism with a payload (mass kg, 0 < mass <= 1e30, inertia kg m^2 about its
    centre, 0 <= inertia <= 1e30: the model file's bounds) at ``point``, added as a part of
    the body carrying it (``body``: which, when several do)."""
    if not 0 < _number(mass) <= MAX_MASS:
        raise SizingError(f"mass: the payload's mass must be a number > 0 kg and <= {MAX_MASS:g}, got {mass!r}", "mass")
    if not 0 <= _number(inertia) <= MAX_MASS:
        raise SizingError(f"inertia: the payload's inertia about its centre must be a number >= 0 kg m^2 and <= "
                          f"{MAX_MASS:g}, got {inertia!r}", "inertia")
    model = copy.deepcopy(mech.to_dict())
    carriers = [b for b, spec in model["bodies"].items() if point in spec.get("points", [])]
    if body is None:
        if not carriers:
            raise SizingError(f"point: no body carries point {point!r}; the points are {', '.join(mech.point_names)}",
                              "point")
        body = carriers[0]
    elif body not in carriers:
        raise SizingError(f"body: {body!r} does not carry point {point!r}; these do: {', '.join(carriers)}", "body")
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

    def __post_init__(self) -> None:
        limit, demand = _number(self.limit), _number(self.demand)
        if not (np.isfinite(limit) and limit > 0):
            raise SizingError(f"limit: a {self.quantity} limit must be a finite number > 0 {self.unit}, got "
                              f"{self.limit!r}", "limit")
        if not demand >= 0:
            raise SizingError(f"demand: the {self.quantity} demand must be >= 0 {self.unit}, got {self.demand!r}",
                              "demand")

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

    def __repr__(self) -> str:
        return (f"MotorSizing({self.name}: peak {self.peak_torque:.4g} N m, RMS {self.rms_torque:.4g} N m, "
                f"speed {self.peak_speed:.4g} rad/s, power {self.peak_power:.4g} W, "
                f"{'pass' if self.passed else 'FAIL'} on {len(self.checks)} limits)")


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

    def __repr__(self) -> str:
        return (f"DriveSizing({self.name}: peak {self.peak_effort:.4g} {self.effort_unit}, RMS {self.rms_effort:.4g} "
                f"{self.effort_unit}, speed {self.peak_speed:.4g} {self.speed_unit}, power {self.peak_power:.4g} W"
                + ("" if self.motor is None else f", motor {self.motor.name}") + ")")


@dataclass
class SizingReport(Summarized):
    """Actuator requirements of a task-space motion; ``drives`` one :class:`DriveSizing` each.

    ``min_sigma_I``/``min_sigma_II`` (dimensionless) with the time (s) and end-effector
    position (m) where each is reached: the motion's nearest approach to each singularity.
    ``first_frequency``: for a model with a ``compliance:`` section, the lowest first natural
    frequency (Hz) over the motion's samples, rotors held (docs/stiffness.md), with its time
    (s) and end-effector position (m); None for a rigid model.
    """

    motion: TaskMotion
    payload: float
    drives: list[DriveSizing]
    min_sigma_I: tuple[float, float, FloatArray]
    min_sigma_II: tuple[float, float, FloatArray]
    first_frequency: tuple[float, float, FloatArray] | None = None

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
        lines.extend(f"{name}: {value}" for name, value in self._frequency_rows())
        return "\n".join(lines)

    def _frequency_rows(self) -> list[tuple[str, str]]:
        if self.first_frequency is None:
            return []
        f, t, X = self.first_frequency
        return [("lowest first natural frequency", f"{f:.4g} Hz at t = {t:.3f} s, end effector at "
                                                   f"({X[0]:.4f}, {X[1]:.4f}) m")]

    def __repr__(self) -> str:
        m = self.motion
        peaks = ", ".join(f"{d.name} {d.peak_effort:.4g} {d.effort_unit}" for d in self.drives)
        motors = [d.motor for d in self.drives if d.motor is not None]
        verdict = "" if not motors else f", motors {'pass' if all(mo.passed for mo in motors) else 'FAIL'}"
        return (f"SizingReport({m.mech.name} on {m.label}: peak efforts {peaks}{verdict}; "
                f"min sigma_II {self.min_sigma_II[0]:.3g})")

    def _summary_rows(self) -> list[tuple[str, str]]:
        m = self.motion
        rows = [("model", m.mech.name), ("path", m.label), ("payload", f"{self.payload:g} kg"),
                ("samples", f"{len(m.t)}, t = {m.t[0]:.6g} .. {m.t[-1]:.6g} s")]
        for kind, (s, t, X) in (("I", self.min_sigma_I), ("II", self.min_sigma_II)):
            rows.append((f"nearest type {kind} singularity",
                         f"sigma_{kind} = {s:.3g} at t = {t:.3f} s, end effector at ({X[0]:.4f}, {X[1]:.4f}) m"))
        return rows + self._frequency_rows()

    def _summary_tables(self) -> list[tuple[list[str], list[list[str]]]]:
        drives = (["drive", "peak effort", "RMS effort", "peak speed", "peak power"],
                  [[d.name, f"{d.peak_effort:.4g} {d.effort_unit}", f"{d.rms_effort:.4g} {d.effort_unit}",
                    f"{d.peak_speed:.4g} {d.speed_unit}", f"{d.peak_power:.4g} W"] for d in self.drives])
        checks = [[d.name, d.motor.name, c.quantity, f"{c.demand:.4g} {c.unit}", f"{c.limit:.4g} {c.unit}",
                   f"{100 * c.margin:.2f} %", "pass" if c.passed else "FAIL"]
                  for d in self.drives if d.motor is not None for c in d.motor.checks]
        header = ["drive", "motor", "limit", "demand", "limit value", "margin", ""]
        return [drives] + ([(header, checks)] if checks else [])

    def to_dict(self) -> dict[str, Any]:
        """Plain numbers (for JSON): per drive the peaks and RMS, and the singularity margins."""
        return {
            "model": self.motion.mech.name, "path": self.motion.label, "payload_kg": self.payload,
            "drives": [{k: getattr(d, k) for k in ("name", "effort_unit", "speed_unit", "peak_effort", "rms_effort",
                                                   "peak_speed", "peak_power")}
                       | ({} if d.motor is None else {"motor": _motor_dict(d.motor)}) for d in self.drives],
            "min_sigma_I": {"value": self.min_sigma_I[0], "t": self.min_sigma_I[1], "X": self.min_sigma_I[2].tolist()},
            "min_sigma_II": {"value": self.min_sigma_II[0], "t": self.min_sigma_II[1], "X": self.min_sigma_II[2].tolist()},
        } | ({} if self.first_frequency is None else {"first_frequency_hz": {
            "value": self.first_frequency[0], "t": self.first_frequency[1], "X": self.first_frequency[2].tolist()}})


def _motor_dict(mo: MotorSizing) -> dict[str, Any]:
    return {"name": mo.name, "peak_torque": mo.peak_torque, "rms_torque": mo.rms_torque, "peak_speed": mo.peak_speed,
            "peak_power": mo.peak_power, "passed": mo.passed,
            "checks": [{"quantity": c.quantity, "demand": c.demand, "limit": c.limit, "unit": c.unit,
                        "margin": c.margin, "passed": c.passed} for c in mo.checks]}


def motor_sizing(mech: Mechanism, k: int, t: FloatArray, qd: FloatArray, torques: FloatArray,
                 dense: tuple[FloatArray, FloatArray] | None = None) -> MotorSizing | None:
    """The motor side of actuator ``k``'s drive along samples at times ``t`` (s) with the
    actuators' rates ``qd`` and motor torques ``torques`` (N m; N, m; or N, n_a with the pair
    actuators: :meth:`Mechanism.motor_torques`, a solved motion's ``tau_motor``); None
    without a motor. ``dense``: the rates and motor torques (M, m or n_a) at more samples (the
    resampling around peaks), from which the peaks are taken too (the RMS is the samples'
    integral)."""
    names = mech.actuator_names
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k < len(names):
        raise SizingError(f"k: an actuator index from 0 to {len(names) - 1} ({', '.join(names)}), got {k!r}", "k")
    t, qd, torques = _samples_of(t, qd, torques, len(names) if np.shape(torques)[-1:] == (len(names),) else mech.dof)
    if dense is not None:
        dense = (_finite("dense", dense[0], qd.shape[1]), _finite("dense", dense[1], qd.shape[1]))
    act = mech.actuators[k]
    if act is None:
        return None
    t_m = torques[:, k]
    qd_all, tm_all = (qd, t_m) if dense is None else (np.vstack([qd, dense[0]]), np.concatenate([t_m, dense[1][:, k]]))
    w = act["gear_ratio"] * qd_all[:, k]
    peak_t, rms_t, peak_w = float(np.abs(tm_all).max()), _rms(t, t_m), float(np.abs(w).max())
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
        checks.append(LimitCheck("torque-speed", float(_usage(tm_all, available).max()), 1.0, "of env"))
    return MotorSizing(act["name"], t_m, act["gear_ratio"] * qd[:, k], peak_t, rms_t, peak_w,
                       float(np.abs(tm_all * w).max()), checks, env_w, np.zeros_like(env_w) if env_t is None else env_t)


def _number(value: Any) -> float:
    """A real number as a float; NaN for anything else (a bool, a string, None)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        return np.nan
    try:
        return float(value)
    except OverflowError:  # an integer beyond the float range
        return np.inf


def _finite(name: str, value: Any, width: int | None = None) -> FloatArray:
    """(N,) finite values, or (N, width) with a width; else a SizingError naming the argument."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        a = np.full(0, np.nan)
    want = (1,) if width is None else (2,)
    if a.ndim not in want or len(a) < 1 or (width is not None and a.shape[1] != width) or not np.all(np.isfinite(a)):
        raise SizingError(f"{name}: expected {'(N,)' if width is None else f'(N, {width})'} finite values, got "
                          f"shape {a.shape}", name)
    return a


def _samples_of(t: Any, qd: Any, torques: Any, width: int) -> tuple[FloatArray, FloatArray, FloatArray]:
    """t (N,) increasing, qd and torques (N, width), all finite, or a SizingError."""
    tt, rates, efforts = _finite("t", t), _finite("qd", qd, width), _finite("torques", torques, width)
    if np.any(np.diff(tt) <= 0):
        raise SizingError("t: expected increasing times (s)", "t")
    for name, rows in (("qd", rates), ("torques", efforts)):
        if len(rows) != len(tt):
            raise SizingError(f"{name}: one row per time, got {len(rows)} rows for {len(tt)} times", name)
    return tt, rates, efforts


def _usage(t_m: FloatArray, available: FloatArray) -> FloatArray:
    """|t_m| / available torque, inf where none is available and some is asked."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(available > 0, np.abs(t_m) / np.where(available > 0, available, 1.0),
                        np.where(np.abs(t_m) > 0, np.inf, 0.0))


def envelope(speed: FloatArray, effort: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Torque-speed envelope: for each speed v, the largest |effort| needed at a speed >= v
    (a staircase falling with speed); a motor whose continuous curve lies above it can drive
    the motion. ``speed``, ``effort`` (N,) finite. Returns (speeds ascending, efforts), both >= 0."""
    v, e = np.abs(_finite("speed", speed)), np.abs(_finite("effort", effort))
    if len(v) != len(e):
        raise SizingError(f"effort: one per speed, got {len(e)} for {len(v)}", "effort")
    order = np.argsort(-v)
    env = np.maximum.accumulate(e[order])
    return v[order][::-1], env[::-1]


def _rms(t: FloatArray, y: FloatArray) -> float:
    """The RMS over [t_0, t_N] by Simpson's rule (the trapezoidal rule for two samples)."""
    from scipy.integrate import simpson

    if len(t) < 2:
        return float(np.abs(y).max()) if len(y) else 0.0
    return float(np.sqrt(max(float(simpson(y**2, x=t)), 0.0) / (t[-1] - t[0])))


@dataclass
class _Samples:
    """What a sizing reads at samples of a motion: times (N,) (s), every actuator's effort,
    rate and motor torque (N, n_a; the effort itself without a motor), the singularity
    measures (N,) and the task coordinates (N, k)."""

    t: FloatArray
    efforts: FloatArray
    rates: FloatArray
    torques: FloatArray
    sigma_I: FloatArray
    sigma_II: FloatArray
    X: FloatArray

    def join(self, other: _Samples) -> _Samples:
        order = np.argsort(np.concatenate([self.t, other.t]), kind="stable")
        return _Samples(*(np.concatenate([getattr(self, f), getattr(other, f)])[order]
                          for f in ("t", "efforts", "rates", "torques", "sigma_I", "sigma_II", "X")))

    def peaks(self, mech: Mechanism) -> list[FloatArray]:
        """The quantities whose largest a sizing reports: |effort|, |rate|, |power| and the
        motor torques per actuator, 1 / sigma for the singularity margins."""
        out = [np.abs(self.efforts), np.abs(self.rates), np.abs(self.efforts * self.rates)]
        if any(a is not None for a in mech.actuators):
            out.append(np.abs(self.torques))
        cols = [c for block in out for c in block.T]
        with np.errstate(divide="ignore"):
            return [*cols, 1 / self.sigma_I, 1 / self.sigma_II]


def _samples(motion: TaskMotion, distribution: str, preload: list[float] | None) -> _Samples:
    mech = motion.mech
    if len(mech.actuator_names) > len(mech.coordinate_names):
        efforts, rates, torques = distributed_efforts(mech, motion, distribution, preload)
    else:
        efforts, rates = motion.tau, motion.qd
        torques = (np.asarray(mech.motor_torques(motion.q, motion.qd, motion.qdd, motion.tau, allow_singular=True))
                   if motion.tau_motor is None else motion.tau_motor)
    return _Samples(motion.t, efforts, rates, torques, motion.sigma_I, motion.sigma_II, motion.X)


def _window(ee: EndEffector, path: TaskPath, motion: TaskMotion, k: int, options: dict[str, Any]) -> TaskMotion:
    """The motion solved FINE times finer over the two sample intervals around sample k,
    continued from the sample before them."""
    i, j = max(k - 1, 0), min(k + 1, len(motion.t) - 1)
    t0 = float(motion.t[i])
    local = TaskPath(float(motion.t[j]) - t0, path.dim, path.label, lambda t: path.sample(t + t0))
    tol = {"singular_tol": options["singular_tol"]} if "singular_tol" in options else {}
    part = solve_motion(ee, local, n=FINE + 1, q_start=motion.q[i], **tol)
    part.t = part.t + t0
    return part


def distributed_efforts(mech: Mechanism, motion: TaskMotion, distribution: str = "min_norm",
                        preload: list[float] | None = None) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Every actuator's effort (N, n_a) along a motion of a redundantly actuated mechanism,
    shared by ``distribution`` (:meth:`Mechanism.distribute_efforts`), each actuator's rate
    (N, n_a): B^T qd (rad/s or m/s on its pair), and its motor torque (N, n_a)."""
    preload = _check_arguments(0.0, distribution, preload, {})[1]
    efforts, rates, torques = [], [], []
    for q, qd, qdd in zip(motion.q, motion.qd, motion.qdd):
        out = mech.distribute_efforts(q, qd, qdd, distribution, preload)  # type: ignore[arg-type]
        efforts.append(out["efforts"])
        rates.append(out["B"].T @ qd)
        torques.append(out["motor_torques"])
    return np.array(efforts), np.array(rates), np.array(torques)


def size(motion: TaskMotion | EndEffector, path: TaskPath | None = None, *, payload: float = 0.0,
         distribution: str = "min_norm", preload: ArrayLike | None = None, **solve_options: Any) -> SizingReport:
    """Actuator sizing report of a task-space motion, its peaks held between the samples.

    Parameters
    ----------
    motion : TaskMotion or EndEffector
        A solved motion (sized on its samples, refused when they do not resolve it); or an
        end effector, with ``path``, to solve (with ``payload``): the sampling is refused
        when it does not resolve the path, and the motion is solved again FINE times finer
        around every sampled peak (planardyn.robot.sampling), so that the peaks, the
        torque-speed check and the singularity margins hold between the samples.
    path : TaskPath
        The motion to size when ``motion`` is an end effector.
    payload : float
        Mass (kg, >= 0) added at the end-effector point first (:func:`with_payload`); only
        with an end effector and a path (a solved motion already has its model).
    distribution, preload
        With more actuators than coordinates (``actuators: [{pair: ...}]``), how their
        efforts are shared: ``"min_norm"``, ``"min_max"`` or ``"preload"`` with ``preload``
        (N m or N per internal force, finite; :meth:`Mechanism.distribute_efforts`); every
        actuator is then sized.
    solve_options
        Passed to :func:`solve_motion` (``dt`` s > 0, ``n`` >= 2, ``q_start``,
        ``singular_tol``); the same defaults.

    Raises
    ------
    SizingError
        An argument out of its range (``argument`` names it); SamplingError (one) a
        sampling too coarse for the path, with a spacing that would do.
    """
    payload, preload = _check_arguments(payload, distribution, preload, solve_options)
    if isinstance(motion, EndEffector):
        if not isinstance(path, TaskPath):
            raise SizingError(f"path: size(effector, path) needs the TaskPath to size, got {path!r}", "path")
        ee = motion
        if payload:
            mech = with_payload(ee.mech, ee.point, payload, body=ee.body)
            ee = EndEffector(mech, ee.point, ee.body)
        dt = solve_options.get("dt")
        if solve_options.get("n") is None and dt is not None and path.duration / dt >= MAX_SAMPLES:
            raise SizingError(f"dt: {dt:g} s makes {path.duration / dt:.3g} samples of the {path.duration:g} s path, more "
                              f"than {MAX_SAMPLES}; give a larger spacing", "dt")
        check_path(path, _sample_times(path.duration, solve_options.get("n"), dt))
        motion = solve_motion(ee, path, **solve_options)
        base = _samples(motion, distribution, preload)
        dense = base
        for k in peak_windows(base.peaks(motion.mech)):
            dense = dense.join(_samples(_window(ee, path, motion, k, solve_options), distribution, preload))
    elif isinstance(motion, TaskMotion):
        if payload or path is not None or solve_options:
            raise SizingError("motion: a solved motion already has its model, path and samples: pass "
                              "size(effector, path, payload=..., dt=...)", "motion")
        check_samples(motion.t, motion.X, motion.Xd)
        base = dense = _samples(motion, distribution, preload)
    else:
        raise SizingError(f"motion: a TaskMotion or an EndEffector, got {type(motion).__name__}", "motion")
    mech = motion.mech
    check_rms(base.t, np.hstack([base.efforts, base.torques]))
    return _report(motion, payload, base, dense)


def _report(motion: TaskMotion, payload: float, base: _Samples, dense: _Samples) -> SizingReport:
    mech = motion.mech
    kinds = mech.actuator_kinds
    drives = []
    for k, name in enumerate(mech.actuator_names):
        tau, qd = dense.efforts[:, k], dense.rates[:, k]
        ev, ee_ = envelope(qd, tau)
        angle = kinds[k] == "angle"
        drives.append(DriveSizing(name, "N m" if angle else "N", "rad/s" if angle else "m/s", float(np.abs(tau).max()),
                                  _rms(base.t, base.efforts[:, k]), float(np.abs(qd).max()),
                                  float(np.abs(tau * qd).max()), ev, ee_,
                                  motor_sizing(mech, k, base.t, base.rates, base.torques, (dense.rates, dense.torques))))
    iI, iII = int(np.argmin(dense.sigma_I)), int(np.argmin(dense.sigma_II))
    return SizingReport(motion, float(payload), drives,
                        (float(dense.sigma_I[iI]), float(dense.t[iI]), dense.X[iI]),
                        (float(dense.sigma_II[iII]), float(dense.t[iII]), dense.X[iII]), _first_frequency(motion))


def lowest_first_frequency(mech: Mechanism, t: FloatArray, q: FloatArray) -> tuple[float, float, int] | None:
    """The lowest first natural frequency (Hz) of the model with its compliances, rotors held
    (docs/stiffness.md), over the poses ``q`` (N, m) a motion reaches at times ``t`` (N,) (s),
    with that time and the pose's row; None without a ``compliance:`` section. Not resampled
    between the poses (it varies with the pose only, slowly away from singularities)."""
    if "compliance" not in mech.to_dict():
        return None
    f = np.array([native_modes(mech._native, row)["omega"][0] for row in q]) / (2 * np.pi)
    i = int(np.argmin(f))
    return float(f[i]), float(t[i]), i


def _first_frequency(motion: TaskMotion) -> tuple[float, float, FloatArray] | None:
    """The lowest first natural frequency (Hz) over the motion's samples, its time and task
    position; None without a ``compliance:`` section."""
    lowest = lowest_first_frequency(motion.mech, motion.t, motion.q)
    if lowest is None:
        return None
    f, t, i = lowest
    return f, t, motion.X[i]


def _check_arguments(payload: Any, distribution: Any, preload: Any,
                     options: dict[str, Any]) -> tuple[float, list[float] | None]:
    """One rule per argument of :func:`size`; the checked payload and preload."""
    mass = _number(payload)
    if not 0 <= mass <= MAX_MASS:
        raise SizingError(f"payload: a mass >= 0 kg and <= {MAX_MASS:g}, got {payload!r}", "payload")
    if distribution not in DISTRIBUTIONS:
        raise SizingError(f"distribution: one of {', '.join(DISTRIBUTIONS)}, got {distribution!r}", "distribution")
    if preload is not None:
        try:
            values = np.atleast_1d(np.asarray(preload, dtype=float))
        except (TypeError, ValueError):
            values = np.full(1, np.nan)
        if values.ndim != 1 or not np.all(np.isfinite(values)):
            raise SizingError(f"preload: finite values (N m or N), one per internal force, got {preload!r}", "preload")
        preload = values.tolist()
    unknown = set(options) - {"dt", "n", "q_start", "singular_tol"}
    if unknown:
        raise SizingError(f"{', '.join(sorted(unknown))}: not an option of size (dt, n, q_start, singular_tol)",
                          sorted(unknown)[0])
    for name in ("dt", "singular_tol"):
        value = options.get(name)
        if value is not None and not (np.isfinite(x := _number(value)) and x > 0):
            raise SizingError(f"{name}: a finite number > 0{' (s)' if name == 'dt' else ''}, got {value!r}", name)
    n = options.get("n")
    if n is not None and (isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 2 <= n <= MAX_SAMPLES):
        raise SizingError(f"n: an integer from 2 to {MAX_SAMPLES}, got {n!r}", "n")
    return mass, preload
