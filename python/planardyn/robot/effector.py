"""The end effector of a robot: its task coordinates X(q), the Jacobian J = dX/dq, the
convective term d2X/dq2 [qd, qd], the type I measure, and inverse kinematics by Newton.

Task coordinates (k = m of them, so J is square):

- m = 2: the position [x, y] (m) of a named point of a body;
- m = 3: the pose [x, y, psi] of the body carrying that point, psi = phi - phi_drawn (rad),
  the body's rotation from its drawn orientation.

The computations are the core's (``planardyn::kinematics::effector``, bound as
``planardyn._core.Effector``); this class gives them a typed face. Inverse kinematics keeps
the branch it starts on: every Newton iterate is reached by continuation from the last.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._core import Effector as _Effector
from .._core import SingularityError

if TYPE_CHECKING:
    from ..mechanism import Mechanism

FloatArray = NDArray[np.float64]


@dataclass
class EffectorState:
    """The end effector at one configuration (what one kinematics call gives).

    ``q`` (m,), ``X`` (k,) task coordinates (m, m[, rad]), ``J`` (k, m) = dX/dq,
    ``sigma_I`` type I measure, ``sigma_II`` type II measure (both dimensionless, 0 at the
    singularity), ``kin`` the :meth:`Mechanism.kinematics` dict (its ``x`` (3n,) the body
    coordinates, the branch to continue from).
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
        self._core = _Effector(mech._native, point, body)
        self.mech = mech
        self.point = point
        self.body = self._core.body
        self.dim = self._core.dim
        # Input scale (rad for angles, L for displacements) of the jump tests in robot.maps.
        self._input_scale = np.array([1.0 if k == "angle" else mech.scale for k in mech.coordinate_kinds])

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

    def task(self, kin: dict[str, Any]) -> FloatArray:
        """(k,) task coordinates from a kinematics dict (m, m[, rad])."""
        return self._core.pose(kin["x"])

    def jacobian(self, kin: dict[str, Any]) -> FloatArray:
        """(k, m) J = dX/dq from the velocity analogues at the kinematics dict's ``x``."""
        return self._core.jacobian(kin["x"])

    def convective(self, kin: dict[str, Any], qd: ArrayLike) -> FloatArray:
        """(k,) d2X/dq2 [qd, qd] = (dJ/dt) qd from the acceleration analogues (m/s^2, rad/s^2)."""
        return self._core.convective(kin["x"], qd)

    def sigma_I(self, J: ArrayLike) -> float:
        """Type I (serial) measure: the smallest singular value of J scaled dimensionless
        (rows by L for positions, columns by 1/L for displacement inputs); 0 where the end
        effector cannot move in some direction."""
        return self._core.measures(J)[0]

    def condition(self, J: ArrayLike) -> float:
        """Condition number of the scaled J (1 = isotropic, inf at a type I singularity)."""
        return self._core.measures(J)[1]

    def _state(self, d: dict[str, Any]) -> EffectorState:
        kin = self.mech.kinematics(d["q"], x_start=d["x"])
        return EffectorState(d["q"], d["X"], d["J"], d["sigma_I"], float(kin["sigma_min"]), kin)

    def state(self, q: ArrayLike, x_start: ArrayLike | None = None) -> EffectorState:
        """The end effector at q (rad or m), reached by continuation from the body coordinates
        ``x_start`` (3n,) when given, else from the drawing (raises AssemblyError /
        SingularityError as kinematics does)."""
        return self._state(self._core.state(q, x_start))

    def home(self) -> FloatArray:
        """(k,) task coordinates in the drawing."""
        return self.state(self.mech.drawn_q).X

    # ------------------------------------------------------------------ inverse kinematics

    def solve(self, X: ArrayLike, q_guess: ArrayLike, x_start: ArrayLike | None = None) -> EffectorState:
        """Inverse kinematics by Newton on q from a nearby guess (same working mode).

        Parameters
        ----------
        X : (k,) array_like
            Target task coordinates (m, m[, rad]).
        q_guess : (m,) array_like
            Start of the iteration (rad or m), e.g. the previous point of a path.
        x_start : (3n,) array_like, optional
            Body coordinates on the wanted branch (e.g. ``state.kin['x']`` of the previous
            point); default the drawing.

        Raises
        ------
        AssemblyError
            No convergence (the target is out of reach on this working mode).
        SingularityError
            From the kinematics, where the analogues are undefined (type II).
        """
        return self._state(self._core.solve(X, q_guess, x_start))

    def inverse(self, X: ArrayLike, q_start: ArrayLike | None = None, x_start: ArrayLike | None = None) -> EffectorState:
        """Inverse kinematics by continuation from a known configuration (default the
        drawing) along the straight task-space segment to X, on its working mode."""
        return self._state(self._core.reach(X, q_start, x_start))


__all__ = ["EndEffector", "EffectorState", "SingularityError"]
