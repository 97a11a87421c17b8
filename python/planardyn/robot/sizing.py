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
class DriveSizing:
    """One drive's requirements (units of its coordinate: N m and rad/s, or N and m/s; W)."""

    name: str
    effort_unit: str
    speed_unit: str
    peak_effort: float
    rms_effort: float
    peak_speed: float
    peak_power: float
    envelope_speed: FloatArray
    envelope_effort: FloatArray


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
        for kind, (s, t, X) in (("I", self.min_sigma_I), ("II", self.min_sigma_II)):
            lines.append(f"nearest type {kind} singularity: sigma_{kind} = {s:.3g} at t = {t:.3f} s, "
                         f"end effector at ({X[0]:.4f}, {X[1]:.4f}) m")
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """Plain numbers (for JSON): per drive the peaks and RMS, and the singularity margins."""
        return {
            "model": self.motion.mech.name, "path": self.motion.label, "payload_kg": self.payload,
            "drives": [{k: getattr(d, k) for k in ("name", "effort_unit", "speed_unit", "peak_effort", "rms_effort",
                                                   "peak_speed", "peak_power")} for d in self.drives],
            "min_sigma_I": {"value": self.min_sigma_I[0], "t": self.min_sigma_I[1], "X": self.min_sigma_I[2].tolist()},
            "min_sigma_II": {"value": self.min_sigma_II[0], "t": self.min_sigma_II[1], "X": self.min_sigma_II[2].tolist()},
        }


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


def size(motion: TaskMotion | EndEffector, path: TaskPath | None = None, *, payload: float = 0.0,
         **solve_options: Any) -> SizingReport:
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
    drives = []
    for k, name in enumerate(mech.coordinate_names):
        tau, qd = motion.tau[:, k], motion.qd[:, k]
        ev, ee_ = envelope(qd, tau)
        speed_unit = "rad/s" if mech.coordinate_kinds[k] == "angle" else "m/s"
        drives.append(DriveSizing(name, mech.effort_units[k], speed_unit, float(np.abs(tau).max()), _rms(motion.t, tau),
                                  float(np.abs(qd).max()), float(np.abs(tau * qd).max()), ev, ee_))
    iI, iII = int(np.argmin(motion.sigma_I)), int(np.argmin(motion.sigma_II))
    return SizingReport(motion, float(payload), drives,
                        (float(motion.sigma_I[iI]), float(motion.t[iI]), motion.X[iI]),
                        (float(motion.sigma_II[iII]), float(motion.t[iII]), motion.X[iII]))
