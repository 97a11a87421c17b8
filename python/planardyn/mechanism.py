"""The typed Python face of a mechanism: loading, kinematics, dynamics, simulation.

Notation (the paper's symbols, see ``docs/formulation.md``): m generalized coordinates ``q`` (rad for
an angle, m for a displacement), n mobile bodies, ``x`` the 3n body coordinates
[X, Y, phi] of each centre of mass (m, m, rad), P named points, p pairs.
"""

from __future__ import annotations

import dataclasses
import json
import os
import warnings
from collections.abc import Callable, Mapping, Sequence
from functools import partial
from typing import Any, Generic, Literal, NamedTuple, TypeVar, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._core import ArgumentError, __version__
from ._core import Mechanism as NativeMechanism
from ._core import load as native_load
from ._core import loads as native_loads
from .arguments import array, error, index, number
from .events import Crossing, Event, event_list, native_events
from .guard import ALWAYS_FITS, available_memory, needed_bytes, rows_message
from .models import UnknownModelError
from .models import path as model_path
from .result import PointMotion, RawRun, SimulationInterrupted, SimulationResult
from .results_format import plain
from .settings import check_settings, convert_numbers


class PlanardynWarning(UserWarning):
    """Something a user should know about a model that still works (redundant constraints)."""

FloatArray = NDArray[np.float64]
DriveFunction = Callable[[float, FloatArray, FloatArray], ArrayLike]
ProgressFunction = Callable[[float], Any]
#: A coordinate's motion ``f(t) -> (q, qd, qdd)`` (rad, rad/s, rad/s^2 or m, m/s, m/s^2).
MotionFunction = Callable[[float], tuple[float, float, float]]


T = TypeVar("T")


class _Native(Generic[T]):
    """A read-only attribute of :class:`Mechanism` read from its native mechanism under the
    same name: one typed, documented line in place of a property per attribute."""

    def __init__(self, doc: str) -> None:
        self.__doc__ = doc

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    @overload
    def __get__(self, obj: None, owner: type | None = None) -> _Native[T]: ...
    @overload
    def __get__(self, obj: Mechanism, owner: type | None = None) -> T: ...
    def __get__(self, obj: Mechanism | None, owner: type | None = None) -> T | _Native[T]:
        return self if obj is None else getattr(obj._native, self.name)

    def __set__(self, obj: Mechanism, value: Any) -> None:
        # A data descriptor (like a property without a setter): a Mechanism is immutable.
        raise AttributeError(f"Mechanism.{self.name} is read-only: a Mechanism is immutable")


class _RunFacts(NamedTuple):
    """What every run of a mechanism reads from it, read once: parsing the model dict and the
    native reads at each run were most of a short run's fixed cost in Python."""

    #: :meth:`Mechanism.to_dict`, the one dict the metadata of all its results share.
    model: dict[str, Any]
    source: str
    coordinate_names: list[str]
    coordinate_kinds: list[str]
    body_names: list[str]
    has_actuators: bool
    dof: int
    n_bodies: int
    #: The model file's ``simulate`` output_dt and t_end (s), None where not given.
    output_dt: float | None
    t_end: float | None
    #: Most output rows that always fit (``guard.ALWAYS_FITS``): the memory is not read for them.
    rows_always_fit: float


class Mechanism:
    """An immutable, validated planar mechanism.

    Made by :func:`load`, :func:`loads` or :func:`from_dict`, never changed afterwards.
    Every method computes from scratch at the configuration it is given: positions are
    found by continuation from the drawing, so they stay on the branch (assembly mode)
    the mechanism is drawn in. Methods release the GIL and may be called from threads.
    """

    __slots__ = ("_native", "_facts")

    def __init__(self, native: NativeMechanism) -> None:
        if not isinstance(native, NativeMechanism):
            raise TypeError("use planardyn.load(), loads() or from_dict() to make a Mechanism")
        self._native = native
        #: Read at the first run (`_run_facts`).
        self._facts: _RunFacts | None = None
        for message in native.warnings:
            warnings.warn(f"{native.source}: {message}", PlanardynWarning, stacklevel=3)

    # ------------------------------------------------------------------ description

    @property
    def warnings(self) -> list[str]:
        """What a user should know about the model (redundant constraints and which pairs)."""
        return list(self._native.warnings)

    # Read straight from the native mechanism (read-only; each docstring is the attribute's).
    name: _Native[str] = _Native("The model's ``name``.")
    source: _Native[str] = _Native("Where the model came from: a file path, ``'<string>'`` or ``'<dict>'``.")
    dof: _Native[int] = _Native("Degrees of freedom m, the number of generalized coordinates.")
    n_bodies: _Native[int] = _Native("Number of mobile bodies n (the ground is not counted).")
    coordinate_names: _Native[list[str]] = _Native("Names of the m generalized coordinates, in the order of every q array.")
    coordinate_kinds: _Native[list[str]] = _Native("``'angle'`` (rad) or ``'displacement'`` (m) for each coordinate.")
    body_names: _Native[list[str]] = _Native("Names of the n mobile bodies, in the order of x (3 values each).")
    pair_names: _Native[list[str]] = _Native("Names of the p kinematic pairs (rows of :meth:`reactions`).")
    point_names: _Native[list[str]] = _Native("Names of the P named points (rows of :meth:`point_positions`).")
    ground_points: _Native[list[str]] = _Native("Names of the points the fixed ground carries.")
    q0: _Native[FloatArray] = _Native("(m,) start coordinates of a simulation (rad or m).")
    qd0: _Native[FloatArray] = _Native("(m,) start rates of a simulation (rad/s or m/s).")
    drawn_q: _Native[FloatArray] = _Native("(m,) coordinates in the drawing (rad or m).")
    x0: _Native[FloatArray] = _Native("(3n,) body coordinates [X, Y, phi] per body in the drawing (m, m, rad).")
    masses: _Native[FloatArray] = _Native("(n,) body masses (kg).")
    inertias: _Native[FloatArray] = _Native("(n,) moments of inertia about the centres of mass (kg m^2).")
    scale: _Native[float] = _Native("Characteristic length L (m): the largest distance between two drawn points.")
    gravity: _Native[FloatArray] = _Native("(2,) gravity [g_x, g_y] (m/s^2).")
    body_points: _Native[list[list[tuple[str, tuple[float, float]]]]] = _Native(
        "For each body, its points as ``(name, (s_x, s_y))`` in the body frame (m).\n\n"
        "The body frame has its origin at the centre of mass and turns with the body angle\n"
        "phi: the world position is ``[X, Y] + R(phi) s``."
    )
    pairs: _Native[list[dict[str, Any]]] = _Native(
        "The pairs as dicts: ``name``, ``kind`` (``'revolute'`` | ``'prismatic'`` | ``'gear'``\n"
        "| ``'slot'``), ``bodies`` (a, b) by name (``'ground'`` for the fixed body), ``point``\n"
        "(name; a gear pair's first centre), ``axis`` (unit guide or slot direction in a's frame,\n"
        "or None) and ``rows`` (start, stop): the pair's rows among the pair-constraint rows."
    )
    simulate_defaults: _Native[dict[str, Any]] = _Native("The model file's ``simulate`` section (None for a setting not given).")
    actuators: _Native[list[dict[str, Any] | None]] = _Native(
        "One entry per actuator (the coordinates', then the pair actuators'), None for an ideal effort "
        "source: the motor and transmission (``name``, "
        "``gear_ratio``, ``efficiency``, ``rotor_inertia`` kg m^2, ``viscous`` N m s/rad, ``coulomb`` N m, "
        "``stiction_speed`` rad/s) and its limits (``peak_torque``, ``continuous_torque`` N m, ``max_speed`` rad/s, "
        "None when not given; ``envelope`` (k, 2) [speed, torque] points), docs/actuators.md."
    )

    @property
    def coordinate_units(self) -> list[str]:
        """``'rad'`` or ``'m'`` for each coordinate."""
        return ["rad" if k == "angle" else "m" for k in self.coordinate_kinds]

    @property
    def effort_units(self) -> list[str]:
        """``'N m'`` (torque on an angle) or ``'N'`` (force on a displacement) per coordinate."""
        return ["N m" if k == "angle" else "N" for k in self.coordinate_kinds]

    def to_dict(self) -> dict[str, Any]:
        """The model as a dict in the model-file schema; ``from_dict`` gives it back."""
        return json.loads(self._native.spec_json())

    def _run_facts(self) -> _RunFacts:
        """What every run reads from this mechanism, read at the first run."""
        if self._facts is None:
            defaults = self.simulate_defaults
            self._facts = _RunFacts(self.to_dict(), self.source, self.coordinate_names, self.coordinate_kinds, self.body_names,
                                    any(a is not None for a in self.actuators), self.dof, self.n_bodies,
                                    defaults.get("output_dt"), defaults.get("t_end"),
                                    ALWAYS_FITS / needed_bytes(1, self.dof, self.n_bodies))
        return self._facts

    def _result(self, raw: RawRun, settings: dict[str, Any] | Callable[[], dict[str, Any]]) -> SimulationResult:
        """The result of a run from the native one, its metadata recording ``settings`` (or
        what the callable makes: values the caller could change after the call copied)."""
        f = self._run_facts()
        if not callable(settings):  # plain values now: an array changed after the call is recorded as it was
            settings = {k: v if v is None else plain(v) for k, v in settings.items()}  # most are None
        # The metadata is made at its first read (issue 25 item 4); a partial, not a closure, holds
        # what it needs (a short run's fixed cost: no cells made and freed).
        tau_motor, note = self._result_motor_torques(raw) if f.has_actuators else (None, "")
        return SimulationResult.from_raw(raw, coordinate_names=f.coordinate_names, coordinate_kinds=f.coordinate_kinds,
                                         body_names=f.body_names, metadata=partial(_run_metadata, self, settings),
                                         tau_motor=tau_motor, message_note=note)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Mechanism):
            return NotImplemented
        return self._native.spec_json() == other._native.spec_json()

    def __hash__(self) -> int:
        return hash(self._native.spec_json())

    def __repr__(self) -> str:
        return repr(self._native)

    def __reduce__(self) -> tuple[Any, ...]:
        # Pickled as its model (for multiprocessing): rebuilt and validated on load.
        return (from_dict, (self.to_dict(), self.source))

    # ------------------------------------------------------------------ kinematics

    def assemble(self, q: ArrayLike, x_start: ArrayLike | None = None) -> FloatArray:
        """Body coordinates at given generalized coordinates (position analysis).

        Parameters
        ----------
        q : (m,) array_like
            Generalized coordinates (rad or m).
        x_start : (3n,) array_like, optional
            Body coordinates on the wanted branch (e.g. the previous point of a path):
            continue from there instead of from the drawing, which is faster for nearby q
            and keeps the branch where x_start is.

        Returns
        -------
        x : (3n,) ndarray
            [X, Y, phi] of each body's centre of mass (m, m, rad), on the drawn branch.

        Raises
        ------
        AssemblyError
            The mechanism cannot be assembled at q (or not on its drawn branch).
        ArgumentError
            q has the wrong shape or a non-finite value.
        """
        return self._native.assemble(q, x_start)

    def pair_geometry(self, x: ArrayLike) -> list[dict[str, Any]]:
        """What the drawings show of each pair at body coordinates x (3n,), in world
        coordinates (m), from the core: a dict per pair with ``name``, ``kind``, ``pins``
        [(x, y)] (pin joints), ``blocks`` [(x, y)] (sliding blocks), ``lines``
        [((x, y), (x, y))] (guides, slots, rack pitch lines) and ``circles`` [((x, y), r)]
        (pitch circles)."""
        return self._native.pair_geometry(np.asarray(x, dtype=float))

    def point_positions(self, x: ArrayLike) -> FloatArray:
        """World positions of every named point for given body coordinates.

        Parameters
        ----------
        x : (3n,) or (N, 3n) array_like
            Body coordinates [X, Y, phi] per body (m, m, rad), e.g. ``result.x``.

        Returns
        -------
        (P, 2) or (N, P, 2) ndarray
            Positions (m) in the order of :attr:`point_names`. A point carried by several
            links has one position (taken from its first carrier, the ground first).
        """
        return self._native.point_positions(x)

    def kinematics(self, q: ArrayLike, qd: ArrayLike | None = None, x_start: ArrayLike | None = None) -> dict[str, Any]:
        """Positions, velocity and acceleration analogues, singularity measures at q.

        Parameters
        ----------
        q : (m,) array_like
            Generalized coordinates (rad or m).
        qd : (m,) array_like, optional
            Generalized rates (rad/s or m/s); adds the velocity entries below.
        x_start : (3n,) array_like, optional
            Body coordinates on the wanted branch (e.g. the previous point of a path):
            continue from there instead of from the drawing, which is faster for nearby q
            and keeps the branch where x_start is.

        Returns
        -------
        dict with
            ``x`` (3n,): body coordinates (m, rad); ``poses`` (n, 3): the same per body;
            ``u`` (n, 3, m): velocity analogues dx/dq_j (m/rad, m/m, rad/rad...);
            ``w`` (n, 3, m, m): acceleration analogues d2x/dq_j dq_k (symmetric in j, k);
            ``points`` (P, 2): world positions of the named points (m);
            ``sigma_min``: type II singularity measure, the smallest singular value of the
            scaled Jacobian with q fixed (dimensionless; 0 at a singularity);
            ``sigma_passive``: the same for the pair constraints alone;
            ``residual``: scaled loop-closure residual of the position solve.
            With qd also ``xd`` (3n,): body velocities U qd (m/s, rad/s); ``c`` (3n,):
            convective accelerations sum_jk qd_j qd_k w_jk (m/s^2, rad/s^2);
            ``point_velocities`` (P, 2) (m/s).

        Raises
        ------
        AssemblyError, SingularityError (the analogues are undefined where sigma_min = 0);
        ArgumentError (attribute ``quantity``) where rates so large make xd or c overflow.
        """
        return self._native.kinematics(q, qd, x_start)

    # ------------------------------------------------------------------ dynamics

    def mass_matrix(self, q: ArrayLike, allow_singular: bool = False, x_start: ArrayLike | None = None) -> FloatArray:
        """Generalized mass matrix A = U^T M U at q.

        Parameters
        ----------
        q : (m,) array_like
            Generalized coordinates (rad or m).
        x_start : (3n,) array_like, optional
            Body coordinates near the wanted assembly (a result's ``res.x[k]``): the position is
            assembled from them and keeps their branch; default: the drawing's branch.

        Returns
        -------
        A : (m, m) ndarray
            Symmetric, positive definite away from singularities (kg m^2 for angles,
            kg for displacements, mixed units off the diagonal).

        Raises
        ------
        SingularityError
            Where the scaled type II measure (``kinematics(q)['sigma_min']``) is below
            ``planardyn::dynamics::SINGULAR_SIGMA`` (1e-6): there the results keep no
            reliable digit (attributes ``kind`` 'type_ii', ``sigma_min``). With
            ``allow_singular=True`` the value is computed anyway.
        """
        return self._native.mass_matrix(q, allow_singular, x_start)

    def forward_dynamics(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        t: float = 0.0,
        tau: ArrayLike | None = None,
        allow_singular: bool = False,
        x_start: ArrayLike | None = None,
    ) -> FloatArray:
        """Generalized accelerations from A qdd = b (forward dynamics).

        The position is assembled from q starting at ``x_start``, else at the drawing: at a
        row k of a run that went through a type II singularity onto another branch, pass
        ``x_start=res.x[k]`` for the run's qdd; without it this gives the drawing branch's
        (``reactions(res)`` and ``point_motion(res)`` follow the run's own branch).

        Parameters
        ----------
        q, qd : (m,) array_like
            Coordinates (rad or m) and rates (rad/s or m/s).
        t : float
            Time (s), for the model's drive tables.
        tau : (m,) array_like, optional
            Drive efforts (N m on angles, N on displacements); default: the model's drives at t.
            On a coordinate with an actuator this is its *motor torque* (docs/actuators.md), not
            the joint-side effort :meth:`inverse_dynamics` returns: pass
            ``motor_torques(q, qd, qdd, tau)`` of those to get qdd back.
        x_start : (3n,) array_like, optional
            The branch, as for :meth:`mass_matrix`.

        Returns
        -------
        qdd : (m,) ndarray
            Accelerations (rad/s^2 or m/s^2).

        Raises
        ------
        SingularityError
            Below the type II threshold, as for :meth:`mass_matrix`, unless
            ``allow_singular=True``.
        ArgumentError
            Finite arguments whose result overflows (attribute ``quantity``): try smaller
            efforts or rates.
        """
        return self._native.forward_dynamics(q, qd, number("t", t, "s"), tau, allow_singular, x_start)

    def inverse_dynamics(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        qdd: ArrayLike,
        x: ArrayLike | None = None,
        xd: ArrayLike | None = None,
        allow_singular: bool = False,
    ) -> FloatArray:
        """Drive efforts that produce a motion: tau = A qdd - U^T (f - M c).

        Parameters
        ----------
        q, qd, qdd : (m,) or (N, m) array_like, all of the same shape
            Coordinates (rad or m), rates and accelerations. For (N, m) the rows are a
            trajectory.
        x : (3n,) or (N, 3n) array_like, optional
            The branch: body coordinates at every row (a result's ``x``: exact whatever
            branches the motion went through), or at the first row only. Without them, or
            with the first row only, each row continues from the previous one, and rows that
            go on past one where that branch comes within ``planardyn::batch::BRANCH_SIGMA``
            (0.05) of a type II singularity raise ``SingularityError`` (attributes ``row``,
            ``sigma_min``): there the motion may have left on the other branch, which q
            alone cannot tell.
        xd : array_like of x's shape, optional
            Body rates of x's rows (a result's ``xd``; needs ``x``), used instead of the rates
            solved from qd: near a type II singularity (measure sigma) one rounding unit of
            qd moves those by eps/sigma, and the efforts with them (2.5e-8 N m at sigma
            8.6e-4 on the free-falling five-bar). Rows whose xd are not the rates of their qd
            (J xd = [0; qd] within ``planardyn::batch::RATES_TOL``, 1e-10 of the largest body
            rate) raise
            ``ArgumentError`` naming the row.

        Returns
        -------
        tau : ndarray of the same shape
            Efforts (N m on angles, N on displacements), the model's drives not included;
            joint-side: with the pairs' Coulomb friction; on a coordinate with a motor its
            gear's output, the rotor (before the gear) not included (:meth:`motor_torques`
            gives the motor side).

        Raises
        ------
        SingularityError
            Below the type II threshold, as for :meth:`mass_matrix`, unless
            ``allow_singular=True`` (then every row is computed).
        ArgumentError
            Finite arguments whose result overflows (attribute ``quantity``): try smaller
            efforts or rates.
        """
        return self._native.inverse_dynamics(q, qd, qdd, x, xd, allow_singular)

    def motor_torques(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        qdd: ArrayLike,
        tau: ArrayLike | None = None,
        x: ArrayLike | None = None,
        xd: ArrayLike | None = None,
        allow_singular: bool = False,
    ) -> FloatArray:
        """Motor torques (N m, motor side) along a motion (q, qd, qdd; arguments, branch and
        errors as :meth:`inverse_dynamics`): of the joint-side efforts ``tau`` ((m,) or (N, m),
        e.g. a result's; or every actuator's, (n_a,) or (N, n_a), e.g. shared efforts), or of
        the motion's own inverse dynamics when ``tau`` is None. Each motor's rotor (inertia J)
        turns before its gear, at its housing's rate plus n qd: t_m = J omega_r' + motor
        friction + t, t the gear's input, tau / (n eta) while motoring (tau qd >= 0),
        tau eta_b / n while back-driven (docs/actuators.md); on an actuator without a motor, the
        effort itself."""
        return self._native.motor_torques(q, qd, qdd, tau, x, xd, allow_singular)

    def _result_motor_torques(self, raw: RawRun) -> tuple[FloatArray | None, str]:
        """A result's ``tau_motor``: :meth:`motor_torques` of its rows (``raw``: t, q, qd, qdd,
        tau, x, xd, each (N, ...)) when the model has an actuator, else None; and what the
        result's message adds about rows without them, the core's note ("" when every row has
        them). The rates xd are the run's state, not checked against qd (``recorded``): near a
        fold of prescribed coordinates the two agree only within the integrator's error,
        magnified there. A row whose friction efforts do not settle (or whose gears jam) is NaN,
        the run kept: a run failing at a fold may not settle again at its last rows
        (five-bar-robot at rk4 dt 1e-4, 4 of its 10318 rows); the others' are each row's own
        call's, to the bit."""
        if not self._run_facts().has_actuators:
            return None, ""
        t_m, note = self._native.run_motor_torques(raw["t"], raw["q"], raw["qd"], raw["qdd"], raw["tau"], raw["x"],
                                                   raw["xd"])
        return np.asarray(t_m, dtype=np.float64), "" if note is None else f"; {note}"

    actuator_names: _Native[list[str]] = _Native(
        "The actuators: the coordinates, then the redundant actuators on other pairs (docs/actuators.md)."
    )
    actuator_kinds: _Native[list[str]] = _Native("``'angle'`` or ``'displacement'``: what each actuator's effort turns.")

    def distribute_efforts(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        qdd: ArrayLike,
        method: Literal["min_norm", "min_max", "preload"] = "min_norm",
        preload: ArrayLike | None = None,
        x_start: ArrayLike | None = None,
    ) -> dict[str, FloatArray]:
        """Inverse dynamics with redundant actuators: every actuator's effort for (q, qd, qdd),
        each (m,). ``method``: ``"min_norm"`` (least Euclidean norm), ``"min_max"`` (least
        largest magnitude, any number of internal forces: a linear program), or ``"preload"`` with ``preload`` one value
        (N m or N) per internal force added to the minimum-norm efforts. Returns ``efforts``
        (n_a,), ``B`` (m, n_a) the generalized force per unit effort, ``internal`` (r, n_a) an
        orthonormal basis of the internal forces (B v = 0), ``motor_torques`` (n_a,) every
        actuator's motor torque (N m; the effort itself without a motor). The efforts are
        joint-side, the gears' outputs, shared as the mechanism's linear B allows; each motor
        then adds its rotor's and its friction's torque before its gear (docs/actuators.md)."""
        lam = None if preload is None else array("preload", preload, ndim=(0, 1), what="N m or N").ravel().tolist()
        return self._native.distribute_efforts(q, qd, qdd, method, lam, x_start)

    def forward_dynamics_actuated(self, q: ArrayLike, qd: ArrayLike, efforts: ArrayLike, t: float = 0.0) -> FloatArray:
        """Accelerations qdd (m,) at (q, qd) under every actuator's effort (n_a,, in
        :attr:`actuator_names` order): on a coordinate with a motor its motor torque (N m), as
        in :meth:`forward_dynamics`; the model's drive laws are not evaluated."""
        return self._native.forward_dynamics_actuated(q, qd, efforts, number("t", t, "s"))

    def available_torque(self, coordinate: int, speed: ArrayLike) -> FloatArray | None:
        """The torque (N m) the motor of actuator ``coordinate`` (an index: the coordinates, then the
        pair actuators) can give at motor speeds ``speed`` (rad/s, any shape): its torque-speed
        envelope, else its peak torque; None when it has no motor or no torque limit."""
        k = index("coordinate", coordinate, len(self.actuator_names), "actuators")
        return self._native.available_torque(k, speed)

    def dissipated_power(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        qdd: ArrayLike,
        x: ArrayLike | None = None,
        xd: ArrayLike | None = None,
        allow_singular: bool = False,
    ) -> Any:
        """Power (W, >= 0) the pairs' Coulomb friction dissipates along a motion (arguments as
        :meth:`inverse_dynamics`): a float for one row, (N,) for rows. The drive power
        ``tau . qd`` exceeds the frictionless one by exactly this."""
        return self._native.dissipated_power(q, qd, qdd, x, xd, allow_singular)

    def forward_dynamics_derivatives(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        t: float = 0.0,
        tau: ArrayLike | None = None,
        allow_singular: bool = False,
        x_start: ArrayLike | None = None,
    ) -> dict[str, FloatArray]:
        """Exact first derivatives of forward dynamics (docs/formulation.md, *Derivatives*).

        Parameters
        ----------
        q, qd, t, tau, x_start
            As for :meth:`forward_dynamics`; the efforts are held fixed (a drive that depends
            on q or qd is differentiated as its value at this state).

        Returns
        -------
        dict
            ``qdd`` (m,) and the (m, m) Jacobians ``dq``, ``dqd``, ``dtau`` with entry
            [i, k] = d qdd_i / d q_k (1/s^2), d qdd_i / d qd_k (1/s), d qdd_i / d tau_k
            (the inverse mass matrix).

        Raises
        ------
        SingularityError
            As for :meth:`mass_matrix`.
        """
        return self._native.forward_dynamics_derivatives(q, qd, t, tau, allow_singular, x_start)

    def inverse_dynamics_derivatives(
        self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, allow_singular: bool = False
    ) -> dict[str, FloatArray]:
        """Exact first derivatives of inverse dynamics (docs/formulation.md, *Derivatives*).

        Parameters
        ----------
        q, qd, qdd : (m,) array_like
            Coordinates (rad or m), rates and accelerations, on the branch continued from
            the drawing.

        Returns
        -------
        dict
            ``tau`` (m,) as :meth:`inverse_dynamics` gives it and the (m, m) Jacobians
            ``dq``, ``dqd``, ``dqdd`` (the mass matrix A), entry [i, k] = d tau_i / d (.)_k.

        Raises
        ------
        SingularityError
            As for :meth:`mass_matrix`.
        """
        return self._native.inverse_dynamics_derivatives(q, qd, qdd, allow_singular)

    def reactions(
        self,
        q: ArrayLike | SimulationResult,
        qd: ArrayLike | None = None,
        t: float = 0.0,
        tau: ArrayLike | None = None,
        allow_singular: bool = False,
        x_start: ArrayLike | None = None,
    ) -> FloatArray:
        """Pair reactions during the motion from (q, qd) under drives tau, or along a whole
        trajectory: ``mech.reactions(res)``.

        Parameters
        ----------
        q, qd, t, tau, allow_singular, x_start
            As for :meth:`forward_dynamics`.
        q : SimulationResult
            A run of this mechanism (qd, t, tau not given): every row on its own branch
            (``res.x``) under the efforts the run applied (``res.tau``; with motors their
            torques, ``res.tau_motor``).

        Returns
        -------
        (p, 3) ndarray, or (N, p, 3) along a result
            Per pair (order of :attr:`pair_names`): [F_x, F_y, M], the force (N, global
            frame) and couple (N m) that the pair's first body exerts on its second.

        Raises
        ------
        SingularityError, ArgumentError
            As for :meth:`forward_dynamics`; along a result, with attributes ``row`` and
            ``t`` of the row.
        """
        if isinstance(q, SimulationResult):
            if qd is not None or tau is not None or x_start is not None:
                raise TypeError("reactions(res) takes the result alone: its rows carry q, qd and tau")
            return self._along(q, allow_singular)["reactions"]
        if qd is None:
            raise TypeError("reactions(q, qd, ...) needs qd (or give a SimulationResult alone)")
        return self._native.reactions(q, qd, number("t", t, "s"), tau, allow_singular, x_start)

    def point_motion(self, res: SimulationResult, allow_singular: bool = False) -> PointMotion:
        """Positions, velocities and accelerations of the named points (those a body or the
        ground carries) along a run of this mechanism, each row on its own branch.

        ``mech.point_motion(res)["P"]`` is the (N, 2) position, velocity and acceleration of
        point P; ``.to_dataframe()`` a table indexed by t. Raises as :meth:`reactions`.
        """
        xdd = self._along(res, allow_singular)["xdd"]
        raw = self._native.point_motion(res.x, res.xd, xdd)
        return PointMotion(t=res.t, names=list(raw["names"]), position=raw["position"],
                           velocity=raw["velocity"], acceleration=raw["acceleration"])

    @property
    def inertial_parameters(self) -> dict[str, float]:
        """The model's inertial parameters, by name: per body ``m_<body>`` (kg),
        ``mcx_<body>``, ``mcy_<body>`` (kg m: the mass times the centre of mass in the body's
        frame, whose origin is the drawn centre of mass, so 0 here) and ``I_<body>`` (kg m^2,
        about that origin). The first columns of :meth:`regressor`, in order."""
        return dict(list(self.regressor_parameters.items())[: 4 * self.n_bodies])

    @property
    def regressor_parameters(self) -> dict[str, float]:
        """All the parameters pi of :meth:`regressor`'s columns, by name, in order: the
        :attr:`inertial_parameters`, then the losses' (docs/identification.md, *Losses*): per
        actuator ``J_<actuator>`` (rotor inertia, kg m^2), ``fv_<actuator>`` (motor viscous,
        N m s/rad), ``fc_<actuator>`` (motor Coulomb, N m); per pair with a viscous damper
        (a ``friction`` load's ``viscous``, or a pair spring of zero stiffness) ``fvp_<pair>``
        (its damping); per friction load with ``mu`` ``mu_<pair>`` (the sliding coefficient)
        and ``fcp_<pair>`` (a constant Coulomb effort, 0 in the model)."""
        values, names = self._native.parameters
        return dict(zip(names, values))

    def regressor(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        qdd: ArrayLike,
        x: ArrayLike | None = None,
        xd: ArrayLike | None = None,
        allow_singular: bool = False,
    ) -> tuple[FloatArray, FloatArray]:
        """The dynamics in linear form: the efforts of :meth:`inverse_dynamics` are
        ``Y @ pi + tau_o``, with pi the parameters (:attr:`regressor_parameters`: whatever
        the bodies' values, since the kinematics do not depend on them) and tau_o the efforts
        of the other loads (springs, external forces). On a coordinate with an actuator the
        row is the motor torque (:meth:`motor_torques` of the efforts); the pin friction's
        load and the transmission's branch (motoring or generating) are the model's own, so
        Y @ pi + tau_o is exact at the model's parameters (docs/identification.md, *Losses*).

        Parameters, branch and body rates ``xd`` as :meth:`inverse_dynamics`. Returns
        ``(Y, tau_o)``: (m, p) and (m,), or (N, m, p) and (N, m) for rows.
        """
        out = self._native.regressor(q, qd, qdd, x, xd, allow_singular)
        return out["Y"], out["tau_o"]

    def _along(self, res: SimulationResult, allow_singular: bool) -> dict[str, FloatArray]:
        if list(res.body_names) != self.body_names or res.x.shape[1:] != (3 * len(self.body_names),):
            raise error("result", "the result is not a run of this mechanism (its bodies differ); "
                                  "use pdy.from_result(res) for the mechanism it was made with")
        # The run's drives: the motor torques where the model has motors (res.tau is joint-side).
        drives = res.tau if res.tau_motor is None else res.tau_motor
        return self._native.along(res.t, res.x, res.q, res.qd, drives, allow_singular)

    def energy(self, q: ArrayLike, qd: ArrayLike, x_start: ArrayLike | None = None) -> tuple[float, float]:
        """Kinetic and potential energy (J) at (q, qd): ``(T, V)``, the position reached from
        the body coordinates ``x_start`` (3n,) on the wanted branch when given, else from the
        drawing.

        V counts gravity (zero at y = 0) and the elastic energy of springs. Rates so large that
        T overflows raise ``ArgumentError`` (attribute ``quantity``).
        """
        return self._native.energy(q, qd, x_start)

    # ------------------------------------------------------------------ simulation

    def simulate(
        self,
        t_end: float | None = None,
        *,
        method: Literal["rk4", "dopri5", "rk45", "dop853", "radau5", "radau"] | None = None,
        rtol: float | None = None,
        atol: float | None = None,
        dt: float | None = None,
        t_eval: ArrayLike | None = None,
        output_dt: float | None = None,
        q0: ArrayLike | None = None,
        qd0: ArrayLike | None = None,
        drives: DriveFunction | None = None,
        progress: ProgressFunction | None = None,
        max_steps: int | None = None,
        motion: Mapping[str, float | Mapping[str, ArrayLike] | MotionFunction] | None = None,
        events: Event | Sequence[Event] | None = None,
        dense_output: bool = False,
    ) -> SimulationResult:
        """Integrate the equations of motion from t = 0 (forward dynamics in time).

        Every argument left at None takes the model file's ``simulate`` value, else the
        default shown.

        Parameters
        ----------
        t_end : float
            End time (s); default 1.
        method : str
            ``'dop853'`` (default), ``'dopri5'``, ``'radau5'`` (stiff springs/dampers) or
            ``'rk4'`` (fixed step, needs ``dt``).
        rtol, atol : float
            Relative and absolute tolerances of the adaptive methods (defaults 1e-9, 1e-12),
            each finite and > 0, rtol at most 1 (the rules of :mod:`planardyn.settings`).
        dt : float
            Fixed step (s): required by rk4; for an adaptive method it turns error control off.
        t_eval : (K,) array_like
            Output times (s), increasing, within [0, t_end]. Default: every ``output_dt``,
            else every accepted step.
        output_dt : float
            Spacing of the output times (s) when t_eval is not given.
        q0, qd0 : (m,) array_like
            Start coordinates (rad or m) and rates (rad/s or m/s); default the model's.
        drives : callable ``f(t, q, qd) -> (m,)``, optional
            Drive efforts (N m or N) instead of the model's ``drives``; t in s, q and qd
            (m,) arrays. An exception inside it ends the run with status ``'drive_failed'``
            and the trajectory computed so far.
        progress : callable ``progress(t)``, optional
            Called about 100 times in a run with the time reached (s); returning False
            (not None) or raising stops the run with status ``'cancelled'``.
        max_steps : int
            Most step attempts (accepted and rejected); past it status ``'too_many_steps'``.
            A run whose mean step, after 10,000 attempts, is below
            ``t_end / (10 max_steps)`` cannot finish and stops early with status
            ``'step_size_too_small'`` (efforts too large for the model, or tolerances too
            tight), keeping its last accepted state as the last row.
        motion : dict, optional
            Coordinates driven by motion instead of effort, by name (with those of the model
            file's ``drives: [{coordinate, motion}]``, which an entry here replaces): a number,
            a constant speed (rad/s or m/s) from the start value; a table
            ``{"t": times (s), "q": positions (rad or m)}`` covering [0, t_end], through which
            a C2 cubic spline with not-a-knot ends runs; or a function ``f(t) -> (q, qd,
            qdd)``. Their efforts are the ones the motion needs (in ``tau``; ``drives`` on them
            are not applied), their work is part of ``work``, and the other coordinates move
            freely under their drives.
        events : list, optional
            Events as in scipy's ``solve_ivp`` (:mod:`planardyn.events`; one alone need not be
            in a list): functions
            ``g(t, q, qd) -> float`` with optional attributes ``terminal`` and ``direction``,
            or :class:`planardyn.Crossing` (a coordinate crossing a value). Zeros are found
            where g changes sign between accepted steps and located on the step's own
            interpolant to a few units in the last place of t (``EVENT_XTOL``); they are in
            ``t_events``, ``q_events`` and ``qd_events``. A terminal event ends the run at its
            first zero with status ``'event'`` (``success`` stays True), the last row at that
            time and no output after it. A zero exactly at t = 0 is not an event. An exception
            in g ends the run with status ``'event_failed'``.
        dense_output : bool
            Keep each step's interpolant: ``result.sol(t)`` then gives (q, qd) at any t of
            the run.

        Returns
        -------
        SimulationResult
            The trajectory (even when the run stopped early: check ``success``/``status``).

        Raises
        ------
        SimulationError
            Invalid options (unknown method, rtol or atol <= 0, rk4 without dt...).
        SimulationInterrupted
            Ctrl-C (a KeyboardInterrupt) during the run; its ``result`` is the trajectory so
            far, status ``'cancelled'``.
        AssemblyError, SingularityError
            The start state cannot be assembled, or is singular.
        ArgumentError
            An argument with the wrong shape or a non-finite value.
        """
        # The rules of the settings are the core's, which the run applies (checked once, issue 25
        # item 4); here the numbers are converted, and checked only before their rows are counted.
        f = self._run_facts()
        events = event_list(events)
        numbers = convert_numbers(t_end, rtol, atol, dt, output_dt, max_steps)
        if t_eval is not None or numbers[4] is not None or f.output_dt is not None:
            self._check_rows_fit(numbers, t_eval)
        names = f.coordinate_names
        # Positionally, in the native signature's order (t_end, method, rtol, atol, dt, t_eval,
        # output_dt, q0, qd0, drives, progress, max_steps, motion, events, dense_output):
        # matching 15 keywords cost a short run ~8k instructions (issue 25 item 4).
        raw = self._native.simulate(numbers[0], method, numbers[1], numbers[2], numbers[3], t_eval, numbers[4], q0, qd0,
                                    drives, progress, numbers[5],
                                    None if motion is None else native_motion(motion, names),
                                    native_events(events, names) if events else [], bool(dense_output))
        # The result carries its model and settings, so it can be saved, re-plotted and rerun:
        # the settings as given (_SETTINGS' order), made into a dict at the first read of the
        # metadata; what the caller could change after the call is copied now.
        given = (t_end, method, rtol, atol, dt, output_dt, None if t_eval is None else plain(t_eval),
                 None if q0 is None else plain(q0), None if qd0 is None else plain(qd0), max_steps,
                 "callable" if callable(drives) else drives,
                 None if motion is None else {k: "callable" if callable(v) else v for k, v in motion.items()},
                 None if events is None else [dataclasses.asdict(e) if isinstance(e, Crossing) else "callable"
                                              for e in events],
                 dense_output)
        result = self._result(raw, partial(_simulate_settings, given))
        if "interrupt" in raw:
            raise SimulationInterrupted(result) from raw["interrupt"]
        return result

    def _check_rows_fit(self, numbers: tuple[Any, ...], t_eval: ArrayLike | None) -> None:
        """Refuse up front a run whose output rows cannot fit in the memory available (a run
        that outputs every step has no count known up front); ``numbers`` are the converted
        (t_end, rtol, atol, dt, output_dt, max_steps). The memory is not read for a run whose
        rows always fit (``guard.ALWAYS_FITS``)."""
        f = self._run_facts()
        t_end, output_dt = numbers[0], numbers[4] or f.output_dt
        if t_eval is not None:
            rows = float(np.size(t_eval))
        elif output_dt is not None:
            rows = (t_end or f.t_end or 1.0) / output_dt + 1
        else:
            return
        if rows <= f.rows_always_fit:
            return
        # A setting that breaks its rule (an infinite t_end...) is refused as such, not for its rows.
        check_settings(**dict(zip(("t_end", "rtol", "atol", "dt", "output_dt", "max_steps"), numbers)))
        refused = rows_message(rows, f.dof, f.n_bodies, available_memory())
        if refused:
            raise error("output_dt", f"{refused}: give a larger output_dt, fewer t_eval or a shorter t_end")


def native_motion(
    motion: Mapping[str, float | Mapping[str, ArrayLike] | MotionFunction] | None, names: list[str]
) -> list[tuple[int, Any]] | None:
    """``Mechanism.simulate``'s ``motion`` as the native call takes it: (coordinate index, a
    speed, a (t, q) pair of lists or a callable)."""
    if motion is None:
        return None
    if not isinstance(motion, Mapping):
        raise TypeError(f"motion must be a dict from coordinate names to motions, got {type(motion).__name__}")
    out: list[tuple[int, Any]] = []
    for name, m in motion.items():
        if name not in names:
            raise error("motion", f"motion: unknown coordinate {name!r}; coordinates are: {', '.join(names)}")
        k = names.index(name)
        if isinstance(m, Mapping):
            if set(m) != {"t", "q"}:
                raise error("motion", f"motion of {name!r}: a table is {{'t': times, 'q': positions}}, "
                                      f"got keys {sorted(m)}")
            t, q = (array(f"motion[{name!r}][{key!r}]", m[key], ndim=1) for key in ("t", "q"))
            out.append((k, (t.tolist(), q.tolist())))
        elif callable(m):
            out.append((k, m))
        elif isinstance(m, (int, float, np.integer, np.floating)) and not isinstance(m, bool):
            out.append((k, float(m)))
        else:
            raise TypeError(f"motion of {name!r}: give a speed (a number, rad/s or m/s), a table "
                            f"{{'t': ..., 'q': ...}} or a function f(t) -> (q, qd, qdd); got {type(m).__name__}")
    return out


#: The settings a result of ``Mechanism.simulate`` records, in its metadata's order; then
#: ``events`` (when given) and ``dense_output`` (when True).
_SETTINGS = ("t_end", "method", "rtol", "atol", "dt", "output_dt", "t_eval", "q0", "qd0", "max_steps", "drives", "motion")


def _simulate_settings(given: tuple[Any, ...]) -> dict[str, Any]:
    """The settings record of a ``Mechanism.simulate`` call from the values it was given:
    those of ``_SETTINGS`` in order, then events (None: not given) and dense_output."""
    settings = dict(zip(_SETTINGS, given))
    events, dense_output = given[len(_SETTINGS):]
    if events is not None:
        settings["events"] = events
    if dense_output:
        settings["dense_output"] = True
    return settings


def _run_metadata(mech: Mechanism, settings: dict[str, Any] | Callable[[], dict[str, Any]]) -> dict[str, Any]:
    """The metadata of a run of ``mech`` with ``settings`` (or what the callable makes)."""
    return run_metadata({}, mech, settings() if callable(settings) else settings)


def load(path: str | os.PathLike[str]) -> Mechanism:
    """Load a model file (``.yaml``/``.yml``, or ``.json``; other names are read as YAML).

    Raises
    ------
    ModelError
        The file cannot be read or is not a valid mechanism; the message names the file and
        the field (``bodies.crank.mass``), as do the attributes ``source`` and ``path``.
    """
    return Mechanism(native_load(os.fspath(path)))


class _UnknownExample(UnknownModelError, ArgumentError):
    """No shipped model has the name given to :func:`load_example`: a
    ``models.UnknownModelError`` (a ``KeyError``) and an ``ArgumentError`` (argument ``name``)."""


def load_example(name: str) -> Mechanism:
    """Load a model file shipped with planardyn by name (``"five-bar"``; see ``planardyn.models.names()``).

    Raises
    ------
    planardyn.models.UnknownModelError
        (a ``KeyError``, and an :class:`ArgumentError`) No shipped model has that name; the
        message lists the names there are.
    """
    if not isinstance(name, str):
        raise TypeError(f"name must be a shipped model's name (a string), not {type(name).__name__}")
    try:
        path = model_path(name)
    except UnknownModelError as e:
        err = _UnknownExample(str(e))
        err.argument = "name"
        raise err from None
    return load(path)


def loads(text: str, format: Literal["yaml", "json"] = "yaml", source: str = "<string>") -> Mechanism:
    """Build a mechanism from model text in YAML or JSON; ``source`` names it in messages."""
    return Mechanism(native_loads(text, format, source))


def _json_default(value: Any) -> Any:
    if isinstance(value, (np.ndarray, np.generic)):
        return value.tolist()
    if isinstance(value, (tuple, set)):
        return list(value)
    raise TypeError(f"{type(value).__name__} is not a model value (use numbers, strings, lists and dicts)")


def from_dict(model: Mapping[str, Any], source: str = "<dict>") -> Mechanism:
    """Build a mechanism from a dict in the model-file schema (as ``yaml.safe_load`` gives).

    numpy numbers and arrays are accepted as values. A :class:`ModelError` names the field
    by its path in the dict (``bodies.crank.mass``, ``pairs[2].at``), with no line.
    """
    if not isinstance(model, Mapping):
        raise TypeError(f"from_dict needs a mapping, got {type(model).__name__}")
    return Mechanism(native_loads(json.dumps(model, default=_json_default, allow_nan=True), "data", source))


def from_result(result: SimulationResult) -> Mechanism:
    """The mechanism a result was computed with, rebuilt from ``result.metadata['model']``
    (a results file, or a result of :meth:`Mechanism.simulate`, carries it).

    Raises
    ------
    ArgumentError
        The result does not carry its model (attach it with :func:`attach_metadata`).
    """
    model = result.metadata.get("model")
    if not model:
        raise error("result", "the result does not carry its model (metadata['model']): "
                              "pass the mechanism, or attach it with planardyn.results_io.attach_metadata")
    return from_dict(model, source=result.metadata.get("source") or "<results>")


def attach_metadata(
    result: SimulationResult,
    mechanism: Mechanism | None = None,
    settings: dict[str, Any] | None = None,
    **extra: Any,
) -> SimulationResult:
    """A copy of ``result`` whose ``metadata`` records the model, settings and version.

    Values already in ``result.metadata`` are kept unless given again here.
    """
    return dataclasses.replace(result, metadata=run_metadata(result.metadata, mechanism, settings, **extra))


def run_metadata(
    metadata: Mapping[str, Any],
    mechanism: Mechanism | None = None,
    settings: dict[str, Any] | None = None,
    **extra: Any,
) -> dict[str, Any]:
    """``metadata`` with the model, settings and version of a run recorded (as
    :func:`attach_metadata`); the model dict is the one all results of ``mechanism`` share."""
    meta = dict(metadata)
    meta.setdefault("kind", "simulation")
    meta["planardyn_version"] = meta.get("planardyn_version") or __version__
    if mechanism is not None:
        facts = mechanism._run_facts()
        meta["model"], meta["source"] = facts.model, facts.source
    if settings is not None:
        meta["settings"] = {k: v if v is None else plain(v) for k, v in settings.items()}  # most are None
    meta.update(extra)
    return meta
