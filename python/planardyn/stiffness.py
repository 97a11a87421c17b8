"""Stiffness and vibration of a mechanism with its compliances (docs/stiffness.md).

The model file's ``compliance:`` section gives the elastic elements (drive transmissions,
revolute and prismatic pairs, slender links); the core (``planardyn::elastic``) computes, exactly from the
pair kinds' first and second derivatives:

- :func:`stiffness`: the Cartesian compliance C and stiffness K of a body's point, pose
  p = [x, y, phi] (m, m, rad), in equilibrium with a wrench W = [F_x, F_y, M] (N, N, N m),
  a preload of elastic drives and (``gravity=True``) the model's own gravity (their geometric
  terms included); the weakest direction;
- :func:`deflection`: the point's deflection under W (and gravity), linear and non-linear by
  continuation;
- :func:`modes`: natural frequencies, mode shapes and damping ratios about a pose (with
  ``gravity=True``: the pose as the equilibrium under the model's gravity);
- :func:`small_oscillations`: the modes of a passive mechanism about its equilibrium;
- :func:`state_space`: the linearised model (A, B, C, D) of the rigid mechanism, in
  ``scipy.signal.StateSpace``'s conventions; :func:`compliant_state_space` that of the
  compliant mechanism with its rotors free (the flexible-joint model);
- :func:`simulate_flexible`: a run with compliant drives (the flexible-joint model);
- :func:`stiffness_map` and :func:`along_path`: the weakest stiffness and the first natural
  frequency over a grid of end-effector positions, and along a path (compliance ellipses).

Every stiffness is in N/m, N m/rad (and N/rad, N m/m off the diagonal); every compliance its
inverse; frequencies in rad/s (``frequency``: Hz).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._core import compliant_state_space as native_compliant_state_space
from ._core import deflection as native_deflection
from ._core import equilibrium as native_equilibrium
from ._core import modes as native_modes
from ._core import simulate_flexible as native_simulate_flexible
from ._core import small_oscillations as native_small_oscillations
from ._core import state_space as native_state_space
from ._core import stiffness as native_stiffness
from ._core import weakest_direction as native_weakest_direction
from .mechanism import Mechanism
from .notebook import Summarized
from .robot.effector import EndEffector
from .robot.maps import singularity_map

FloatArray = NDArray[np.float64]

__all__ = [
    "DeflectionReport", "ModesReport", "PathStiffness", "StiffnessMap", "StiffnessReport", "along_path",
    "compliant_state_space", "deflection", "modes", "simulate_flexible", "small_oscillations", "state_space",
    "stiffness", "stiffness_map",
]


def _q(mech: Mechanism, q: ArrayLike | None) -> FloatArray:
    return np.asarray(mech.q0 if q is None else q, dtype=float)


def _matrix(m: Any) -> str:
    return "[" + "; ".join(" ".join(f"{v:.4g}" for v in row) for row in np.atleast_2d(m)) + "]"


def _wrench(w: FloatArray) -> str:
    return f"F_x {w[0]:.4g} N, F_y {w[1]:.4g} N, M {w[2]:.4g} N m"


def _span(values: FloatArray, unit: str) -> str:
    """The range of ``values`` over the cells or poses that have one (NaN: unreachable)."""
    return f"{np.nanmin(values):.6g} .. {np.nanmax(values):.6g} {unit}"


class _Report(Summarized):
    """A report printed as its summary rows, one "field: value" a line."""

    def __str__(self) -> str:
        return "\n".join(f"{k}: {v}" for k, v in self._summary_rows())


@dataclass(frozen=True, repr=False)
class StiffnessReport(_Report):
    """The Cartesian compliance and stiffness of ``point`` of ``body`` at coordinates ``q``.

    ``pose`` (3,) [x, y, phi]; ``compliance`` (3, 3) C; ``stiffness`` (3, 3) K = C^-1, None
    where the point moves in fewer than three directions (``freedoms`` < 3); ``translational``
    (2, 2) the stiffness against a force without moment, C_tt^-1; ``weakest_direction`` (2,)
    the unit direction of the largest translational compliance and ``weakest_stiffness``
    (N/m) its inverse; ``wrench`` (3,) the load it is in equilibrium with.
    """

    body: str
    point: str | None
    q: FloatArray
    wrench: FloatArray
    pose: FloatArray
    compliance: FloatArray
    stiffness: FloatArray | None
    translational: FloatArray | None
    freedoms: int
    weakest_direction: FloatArray
    weakest_stiffness: float

    @classmethod
    def _from(cls, d: dict[str, Any], body: str, point: str | None, q: FloatArray, wrench: FloatArray) -> StiffnessReport:
        return cls(body, point, q, wrench, d["pose"], d["compliance"], d["stiffness"], d["translational"],
                   int(d["freedoms"]), d["weakest_direction"], float(d["weakest_stiffness"]))

    def weakest(self, length: float) -> tuple[FloatArray, float]:
        """The weakest direction [d_x, d_y, length d_phi] of the whole compliance with rotations
        scaled by a characteristic ``length`` (m), and its stiffness (N/m)."""
        direction, k = native_weakest_direction(self.compliance.ravel(), float(length))
        return direction, k

    def ellipse(self) -> tuple[FloatArray, FloatArray]:
        """The translational compliance ellipse: semi-axes (2,) (m/N) and their unit
        directions (2, 2) as columns (displacement under a unit force)."""
        values, vectors = np.linalg.eigh(self.compliance[:2, :2])
        return values, vectors

    def __repr__(self) -> str:
        return (f"StiffnessReport({self.point or 'centre of mass'} of {self.body}: weakest "
                f"{self.weakest_stiffness:.4g} N/m along [{self.weakest_direction[0]:.3f}, "
                f"{self.weakest_direction[1]:.3f}], {self.freedoms} freedoms)")

    def _summary_rows(self) -> list[tuple[str, str]]:
        rows = [("output", f"{self.point or 'centre of mass'} of {self.body}"),
                ("pose", f"x {self.pose[0]:.6g} m, y {self.pose[1]:.6g} m, phi {self.pose[2]:.6g} rad"),
                ("wrench", _wrench(self.wrench)),
                ("compliance C", _matrix(self.compliance)),
                ("stiffness K", _matrix(self.stiffness) if self.stiffness is not None
                 else f"none: the point moves in {self.freedoms} direction(s)"),
                ("weakest", f"{self.weakest_stiffness:.6g} N/m along [{self.weakest_direction[0]:.4f}, "
                            f"{self.weakest_direction[1]:.4f}]")]
        if self.translational is not None:
            rows.insert(5, ("translational K", _matrix(self.translational) + " N/m"))
        return rows


def stiffness(mech: Mechanism, q: ArrayLike | None = None, *, body: str, point: str | None = None,
              wrench: ArrayLike | None = None, preload: Mapping[str, float] | None = None,
              gravity: bool = False) -> StiffnessReport:
    """The Cartesian stiffness of ``point`` of ``body`` (default its centre of mass) at
    coordinates ``q`` (m,) (default the start), in equilibrium with ``wrench`` [F_x, F_y, M]
    (N, N, N m) at the point, ``preload`` efforts (N m or N) of elastic drives by actuator
    name and, with ``gravity``, the model's gravity on its bodies: the elements carry the load
    at that pose. Raises ``ArgumentError`` naming the argument (an unknown body, a rigid
    model...)."""
    qq = _q(mech, q)
    w = np.zeros(3) if wrench is None else np.asarray(wrench, dtype=float)
    d = native_stiffness(mech._native, qq, body, point, w, dict(preload) if preload else None, bool(gravity))
    return StiffnessReport._from(d, body, point, qq, w)


@dataclass(frozen=True, repr=False)
class DeflectionReport(_Report):
    """The deflection of a point under a wrench: ``linear`` C0 W and ``nonlinear`` (3,)
    [dx, dy, dphi] (m, m, rad), ``tangent`` the stiffness at the loaded equilibrium, ``x``
    the body coordinates there."""

    wrench: FloatArray
    linear: FloatArray
    nonlinear: FloatArray
    tangent: StiffnessReport
    x: FloatArray

    def __repr__(self) -> str:
        return (f"DeflectionReport(|d| {np.hypot(*self.nonlinear[:2]):.4g} m non-linear, "
                f"{np.hypot(*self.linear[:2]):.4g} m linear)")

    def _summary_rows(self) -> list[tuple[str, str]]:
        def fmt(d: FloatArray) -> str:
            return f"dx {d[0]:.6g} m, dy {d[1]:.6g} m, dphi {d[2]:.6g} rad"

        return [("wrench", _wrench(self.wrench)),
                ("linear", fmt(self.linear)), ("non-linear", fmt(self.nonlinear)),
                ("tangent weakest", f"{self.tangent.weakest_stiffness:.6g} N/m")]


def deflection(mech: Mechanism, q: ArrayLike | None = None, *, body: str, wrench: ArrayLike,
               point: str | None = None, steps: int = 10,
               preload: Mapping[str, float] | None = None, gravity: bool = False) -> DeflectionReport:
    """The deflection of ``point`` of ``body`` under ``wrench`` (N, N, N m) and, with
    ``gravity``, the model's gravity (the sag), from the pose ``q`` unstrained: linear and
    non-linear (the equilibrium followed in ``steps`` load increments)."""
    qq = _q(mech, q)
    w = np.asarray(wrench, dtype=float)
    d = native_deflection(mech._native, qq, body, w, point, steps, dict(preload) if preload else None, bool(gravity))
    tangent = StiffnessReport._from(d["tangent"], body, point, qq, w)
    return DeflectionReport(w, d["linear"], d["nonlinear"], tangent, d["x"])


@dataclass(frozen=True, repr=False)
class ModesReport(_Report):
    """Natural modes by increasing frequency: ``omega`` (k,) rad/s, ``omega2`` (negative:
    unstable), ``damping_ratio`` (k,) modal, ``shapes`` (k, 3n) body displacements (or (k, m)
    coordinates for small oscillations), mass-normalised."""

    omega: FloatArray
    omega2: FloatArray
    damping_ratio: FloatArray
    shapes: FloatArray
    q: FloatArray

    @property
    def frequency(self) -> FloatArray:
        """Natural frequencies (Hz)."""
        return self.omega / (2 * np.pi)

    @property
    def period(self) -> FloatArray:
        """Periods (s); inf for a zero frequency."""
        with np.errstate(divide="ignore"):
            return np.where(self.omega > 0, 2 * np.pi / np.where(self.omega > 0, self.omega, 1.0), np.inf)

    def __repr__(self) -> str:
        first = f", first {self.frequency[0]:.4g} Hz" if len(self.omega) else ""
        return f"ModesReport({len(self.omega)} modes{first})"

    def _summary_rows(self) -> list[tuple[str, str]]:
        return [(f"mode {k + 1}", f"{f:.6g} Hz ({w:.6g} rad/s), damping ratio {z:.4g}"
                 + (" (unstable)" if w2 < 0 else ""))
                for k, (f, w, z, w2) in enumerate(zip(self.frequency, self.omega, self.damping_ratio, self.omega2))]


def _modes(d: dict[str, Any], q: FloatArray) -> ModesReport:
    return ModesReport(d["omega"], d["omega2"], d["damping_ratio"], d["shapes"], q)


def modes(mech: Mechanism, q: ArrayLike | None = None, *, free_rotors: bool = False,
          gravity: bool = False) -> ModesReport:
    """The natural modes of the compliant mechanism about coordinates ``q`` (its rigid pose):
    each elastic drive's rotor held (a stiff position loop) or free (a torque-driven motor);
    with ``gravity``, about ``q`` as the equilibrium under the model's gravity (its geometric
    stiffness included: a hanging link stiffens, a standing one softens)."""
    qq = _q(mech, q)
    return _modes(native_modes(mech._native, qq, free_rotors, bool(gravity)), qq)


def small_oscillations(mech: Mechanism, q: ArrayLike | None = None, *, equilibrium: bool = True) -> ModesReport:
    """The small oscillations of a passive mechanism (gravity, springs; no drives) about its
    equilibrium nearest ``q`` (``equilibrium`` False: about ``q`` itself)."""
    qq = _q(mech, q)
    if equilibrium:
        qq = native_equilibrium(mech._native, qq)
    return _modes(native_small_oscillations(mech._native, qq), qq)


def state_space(mech: Mechanism, q: ArrayLike | None = None, qd: ArrayLike | None = None,
                tau: ArrayLike | None = None, points: Sequence[tuple[str, str]] = ()
                ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """(A, B, C, D) of the rigid mechanism linearised at (q, qd) with efforts tau held
    (default: at rest, tau the holding efforts), for ``scipy.signal.StateSpace(A, B, C, D)``:
    state [dq; dqd] (2m), input the efforts' increments (m), outputs the coordinates' increments
    and each (body, point)'s [dx, dy] (m)."""
    qq = _q(mech, q)
    rates = np.zeros_like(qq) if qd is None else np.asarray(qd, dtype=float)
    efforts = mech.inverse_dynamics(qq, rates, np.zeros_like(qq)) if tau is None else np.asarray(tau, dtype=float)
    d = native_state_space(mech._native, qq, rates, np.asarray(efforts, dtype=float), list(points))
    return d["A"], d["B"], d["C"], d["D"]


def compliant_state_space(mech: Mechanism, q: ArrayLike | None = None, *, points: Sequence[tuple[str, str]] = (),
                          gravity: bool = False) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """(A, B, C, D) of the compliant mechanism with every elastic drive's rotor free (the
    flexible-joint model of :func:`simulate_flexible`) linearised about coordinates ``q`` as
    its equilibrium (with ``gravity``: under the model's gravity, the motors holding it), for
    ``scipy.signal.StateSpace(A, B, C, D)``. State [xi; dxi/dt] (2h): xi the mass-normalised
    coordinates of its h massive free motions (the eigenvalues of A are +-i omega of
    :func:`modes` with ``free_rotors=True`` when undamped); input the motor torques (motor
    side, N m or N) of the elastic drives with a rotor, in the order of the actuators;
    outputs the coordinates' increments (rad or m, measured at their pairs), then each
    (body, point)'s [dx, dy] (m)."""
    qq = _q(mech, q)
    d = native_compliant_state_space(mech._native, qq, list(points), bool(gravity))
    return d["A"], d["B"], d["C"], d["D"]


@dataclass(repr=False)
class StiffnessMap(_Report):
    """The weakest translational stiffness ``weakest`` (N/m) and the first natural frequency
    ``first_frequency`` (Hz) over a grid of end-effector positions: (ny, nx), NaN where
    unreachable (row j at y[j], column i at x[i])."""

    x: FloatArray
    y: FloatArray
    weakest: FloatArray
    first_frequency: FloatArray

    def __repr__(self) -> str:
        return (f"StiffnessMap({len(self.y)} x {len(self.x)} cells, weakest "
                f"{np.nanmin(self.weakest):.4g} .. {np.nanmax(self.weakest):.4g} N/m)")

    def _summary_rows(self) -> list[tuple[str, str]]:
        return [("cells", f"{len(self.y)} x {len(self.x)}, {int(np.isfinite(self.weakest).sum())} reachable"),
                ("weakest stiffness", _span(self.weakest, "N/m")), ("first frequency", _span(self.first_frequency, "Hz"))]


def stiffness_map(ee: EndEffector, xlim: tuple[float, float], ylim: tuple[float, float],
                  n: int | tuple[int, int] = 30, psi: float = 0.0, gravity: bool = False) -> StiffnessMap:
    """The weakest stiffness of the end-effector point and the first natural frequency over a
    grid of its positions (inverse kinematics by continuation as the singularity maps:
    :func:`planardyn.robot.maps.singularity_map`); with ``gravity``, under the model's gravity."""
    grid = singularity_map(ee, xlim, ylim, n, psi)
    weakest = np.full(grid.sigma_I.shape, np.nan)
    first = np.full(grid.sigma_I.shape, np.nan)
    for j, i in zip(*np.nonzero(grid.reachable)):
        q = grid.q[j, i]
        weakest[j, i] = stiffness(ee.mech, q, body=ee.body, point=ee.point, gravity=gravity).weakest_stiffness
        first[j, i] = modes(ee.mech, q, gravity=gravity).frequency[0]
    return StiffnessMap(grid.x, grid.y, weakest, first)


@dataclass(repr=False)
class PathStiffness(_Report):
    """Along a path's rows of coordinates: ``position`` (N, 2) m, ``ellipses`` (N, 2) the
    translational compliance's semi-axes (m/N) with ``axes`` (N, 2, 2) their directions as
    columns, ``weakest`` (N,) N/m, ``first_frequency`` (N,) Hz."""

    position: FloatArray
    ellipses: FloatArray
    axes: FloatArray
    weakest: FloatArray
    first_frequency: FloatArray

    def __repr__(self) -> str:
        return (f"PathStiffness({len(self.weakest)} poses, first frequency down to "
                f"{self.first_frequency.min():.4g} Hz)")

    def _summary_rows(self) -> list[tuple[str, str]]:
        return [("poses", str(len(self.weakest))),
                ("weakest stiffness", _span(self.weakest, "N/m")), ("first frequency", _span(self.first_frequency, "Hz"))]


def along_path(mech: Mechanism, q: ArrayLike, *, body: str, point: str | None = None,
               gravity: bool = False) -> PathStiffness:
    """Compliance ellipses, weakest stiffness and first frequency at each row of ``q`` (N, m);
    with ``gravity``, under the model's gravity."""
    rows = np.atleast_2d(np.asarray(q, dtype=float))
    reports = [stiffness(mech, r, body=body, point=point, gravity=gravity) for r in rows]
    ellipses = [r.ellipse() for r in reports]
    return PathStiffness(np.array([r.pose[:2] for r in reports]), np.array([e[0] for e in ellipses]),
                         np.array([e[1] for e in ellipses]), np.array([r.weakest_stiffness for r in reports]),
                         np.array([modes(mech, r, gravity=gravity).frequency[0] for r in rows]))


def simulate_flexible(mech: Mechanism, t_end: float, output_dt: float = 1e-3, *, method: str = "dop853",
                      rtol: float = 1e-9, atol: float = 1e-12) -> dict[str, FloatArray]:
    """Simulate with compliant drives: each elastic drive's rotor (``actuators``: ``gear_ratio``
    n, ``rotor_inertia`` J) a coordinate of its own joined to its joint by the transmission's
    spring, the model's drives the motor torques. Returns ``t`` (N,) s, ``q``, ``qd`` (N, m),
    ``theta``, ``thetad`` (N, r) the rotors' angles and rates on the joint side (motor angle / n),
    ``energy`` (N,) J: T + V + the rotors' kinetic and the springs' energy."""
    return native_simulate_flexible(mech._native, float(t_end), float(output_dt), method, rtol, atol)
