"""The end effector of a robot: its task coordinates X(q), the Jacobian J = dX/dq, the
convective term d2X/dq2 [qd, qd], the type I measure, and inverse kinematics by Newton.

Task coordinates (k = m of them, so J is square):

- m = 2: the position [x, y] (m) of a named point of a body;
- m = 3: the pose [x, y, psi] of the body carrying that point, psi = phi - phi_drawn (rad),
  the body's rotation from its drawn orientation.

For point s (body frame, m) of body i with pose [X_i, Y_i, phi_i], P = [X_i, Y_i] + R(phi_i) s,
so with the body's velocity analogues u_ij = d[X_i, Y_i, phi_i]/dq_j and acceleration
analogues w_ijk (E the rotation by +90 deg):

    dP/dq_j          = u_r,ij + u_phi,ij E R s
    d2P/dq_j dq_k    = w_r,ijk + w_phi,ijk E R s - u_phi,ij u_phi,ik R s
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._core import AssemblyError, SingularityError
from .tolerances import IK_TOL

if TYPE_CHECKING:
    from ..mechanism import Mechanism

FloatArray = NDArray[np.float64]

E = np.array([[0.0, -1.0], [1.0, 0.0]])  # rotation by +90 deg: d/dphi R(phi) = E R(phi)

# Newton steps to reach IK_TOL from a predictor or continuation step.
IK_MAX_ITER = 30
# Largest Newton step (rad for an angle input, L for a displacement): keeps a poor guess from
# jumping to another working mode.
IK_MAX_STEP = 0.25
# Continuation from the drawing to a first target: steps of at most this much of L (or rad).
IK_CONTINUATION_STEP = 0.02


def _rot(phi: float) -> FloatArray:
    c, s = np.cos(phi), np.sin(phi)
    return np.array([[c, -s], [s, c]])


@dataclass
class EffectorState:
    """The end effector at one configuration (what one kinematics call gives).

    ``q`` (m,), ``X`` (k,) task coordinates (m, m[, rad]), ``J`` (k, m) = dX/dq,
    ``sigma_I`` type I measure, ``sigma_II`` type II measure (both dimensionless, 0 at the
    singularity), ``kin`` the :meth:`Mechanism.kinematics` dict.
    """

    q: FloatArray
    X: FloatArray
    J: FloatArray
    sigma_I: float
    sigma_II: float
    kin: dict[str, Any]


class EndEffector:
    """A named point of a body (m = 2) or the pose of that body (m = 3) as task coordinates.

    Parameters
    ----------
    mech : Mechanism
        A mechanism with m = 2 or m = 3 generalized coordinates.
    point : str
        A named point (default ``'P'``).
    body : str, optional
        The body carrying it; needed only for m = 3 when several bodies carry the point
        (their angles differ). For m = 2 any carrier gives the same position.
    """

    def __init__(self, mech: Mechanism, point: str = "P", body: str | None = None) -> None:
        if mech.dof not in (2, 3):
            raise ValueError(
                f"task-space motions need m = 2 (a point) or m = 3 (a pose) coordinates; "
                f"{mech.name!r} has m = {mech.dof}"
            )
        carriers = [b for b, pts in zip(mech.body_names, mech.body_points) if point in [n for n, _ in pts]]
        if not carriers:
            raise ValueError(f"no mobile body carries point {point!r}; the points are {', '.join(mech.point_names)}")
        if body is None:
            if mech.dof == 3 and len(carriers) > 1:
                raise ValueError(f"point {point!r} is on {', '.join(carriers)}: say which body's pose with body=")
            body = carriers[0]
        elif body not in carriers:
            raise ValueError(f"body {body!r} does not carry point {point!r} (carried by {', '.join(carriers)})")
        self.mech = mech
        self.point = point
        self.body = body
        self.dim = mech.dof
        self._i = mech.body_names.index(body)
        self._s = np.array(dict(mech.body_points[self._i])[point], dtype=float)
        self._phi0 = float(mech.x0[3 * self._i + 2])
        L = mech.scale
        # Scalings that make J dimensionless: task rows by L (positions), inputs by L (displacements).
        self._task_scale = np.array([L, L, 1.0][: self.dim])
        self._input_scale = np.array([1.0 if k == "angle" else L for k in mech.coordinate_kinds])

    @property
    def names(self) -> list[str]:
        """Names of the task coordinates: ``['x', 'y']`` or ``['x', 'y', 'psi']``."""
        return ["x", "y", "psi"][: self.dim]

    @property
    def units(self) -> list[str]:
        return ["m", "m", "rad"][: self.dim]

    def __repr__(self) -> str:
        what = "position" if self.dim == 2 else "pose"
        return f"EndEffector({what} of point {self.point!r} on {self.body!r})"

    # ------------------------------------------------------------------ X, J, d2X

    def _body(self, kin: dict[str, Any]) -> tuple[FloatArray, FloatArray, FloatArray]:
        pose = kin["poses"][self._i]
        Rs = _rot(pose[2]) @ self._s
        return pose, Rs, kin["u"][self._i]

    def task(self, kin: dict[str, Any]) -> FloatArray:
        """(k,) task coordinates from a kinematics dict (m, m[, rad])."""
        pose, Rs, _ = self._body(kin)
        P = pose[:2] + Rs
        return P if self.dim == 2 else np.array([P[0], P[1], pose[2] - self._phi0])

    def jacobian(self, kin: dict[str, Any]) -> FloatArray:
        """(k, m) J = dX/dq from the velocity analogues: dP/dq_j = u_r,j + u_phi,j E R s."""
        _, Rs, u = self._body(kin)
        JP = u[:2] + np.outer(E @ Rs, u[2])
        return JP if self.dim == 2 else np.vstack([JP, u[2]])

    def convective(self, kin: dict[str, Any], qd: FloatArray) -> FloatArray:
        """(k,) d2X/dq2 [qd, qd] = (dJ/dt) qd from the acceleration analogues (m/s^2, rad/s^2).

        sum_jk qd_j qd_k (w_r,jk + w_phi,jk E R s - u_phi,j u_phi,k R s).
        """
        _, Rs, u = self._body(kin)
        c = kin["w"][self._i] @ qd @ qd  # (3,): sum_jk qd_j qd_k w_jk of the body
        omega = u[2] @ qd
        cP = c[:2] + c[2] * (E @ Rs) - omega**2 * Rs
        return cP if self.dim == 2 else np.array([cP[0], cP[1], c[2]])

    def sigma_I(self, J: FloatArray) -> float:
        """Type I (serial) measure: the smallest singular value of J scaled dimensionless
        (rows by L for positions, columns by 1/L for displacement inputs); 0 where the end
        effector cannot move in some direction."""
        Js = J / self._task_scale[:, None] * self._input_scale[None, :]
        return float(np.linalg.svd(Js, compute_uv=False)[-1])

    def condition(self, J: FloatArray) -> float:
        """Condition number of the scaled J (1 = isotropic, inf at a type I singularity)."""
        Js = J / self._task_scale[:, None] * self._input_scale[None, :]
        sv = np.linalg.svd(Js, compute_uv=False)
        return float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")

    def state(self, q: ArrayLike) -> EffectorState:
        """The end effector at q (raises AssemblyError / SingularityError as kinematics does)."""
        q = np.asarray(q, dtype=float)
        kin = self.mech.kinematics(q)
        J = self.jacobian(kin)
        return EffectorState(q, self.task(kin), J, self.sigma_I(J), float(kin["sigma_min"]), kin)

    def home(self) -> FloatArray:
        """(k,) task coordinates in the drawing."""
        return self.state(self.mech.drawn_q).X

    # ------------------------------------------------------------------ inverse kinematics

    def _scaled(self, r: FloatArray) -> float:
        return float(np.max(np.abs(r / self._task_scale)))

    def solve(self, X: ArrayLike, q_guess: ArrayLike, tol: float = IK_TOL) -> EffectorState:
        """Inverse kinematics by Newton on q from a nearby guess (same working mode).

        Parameters
        ----------
        X : (k,) array_like
            Target task coordinates (m, m[, rad]).
        q_guess : (m,) array_like
            Start of the iteration (rad or m), e.g. the previous point of a path.

        Raises
        ------
        AssemblyError
            No convergence (the target is out of reach on this working mode).
        SingularityError
            From the kinematics, where the analogues are undefined (type II).
        """
        X = np.asarray(X, dtype=float)
        q = np.array(q_guess, dtype=float)
        r = np.full(self.dim, np.inf)
        for _ in range(IK_MAX_ITER):
            st = self.state(q)
            r = X - st.X
            if self._scaled(r) < tol:
                return st
            try:
                dq = np.linalg.solve(st.J, r)
            except np.linalg.LinAlgError:
                break
            big = np.max(np.abs(dq / self._input_scale))
            if big > IK_MAX_STEP:
                dq *= IK_MAX_STEP / big
            q = q + dq
        raise AssemblyError(
            f"inverse kinematics did not converge to X = {np.array2string(X, precision=6)} "
            f"(residual {self._scaled(r):.2e} L after {IK_MAX_ITER} iterations): the target is out of "
            f"reach on this working mode, or at a type I singularity"
        )

    def inverse(self, X: ArrayLike, q_start: ArrayLike | None = None) -> EffectorState:
        """Inverse kinematics by continuation from a known configuration (default the
        drawing) along the straight task-space segment to X, on its working mode."""
        q = self.mech.drawn_q if q_start is None else np.asarray(q_start, dtype=float)
        st = self.state(q)
        X = np.asarray(X, dtype=float)
        d = self._scaled(X - st.X)
        n = max(1, int(np.ceil(d / IK_CONTINUATION_STEP)))
        X0 = st.X
        for a in np.linspace(0.0, 1.0, n + 1)[1:]:
            st = self.solve(X0 + a * (X - X0), st.q)
        return st


__all__ = ["EndEffector", "EffectorState", "SingularityError"]
