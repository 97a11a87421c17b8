"""Typed stub of the native module ``planardyn._core`` (crates/planardyn-py).

Use the package ``planardyn`` instead: its ``Mechanism`` wraps this one with documented
parameters. Arrays are float64, C order, time-major; units SI (m, kg, s, rad, N, N m).
"""

from collections.abc import Callable
from os import PathLike
from typing import Any, final

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "__version__",
    "Mechanism",
    "load",
    "loads",
    "resolve_model",
    "PlanardynError",
    "ModelError",
    "ArgumentError",
    "DataError",
    "AssemblyError",
    "SingularityError",
    "SimulationError",
    "constraint_jacobian",
    "structure",
    "structure_of_model",
    "Effector",
    "DenseOutput",
    "Run",
    "SINGULAR_TOL",
    "JUMP_TOL",
    "MIN_RTOL",
    "MAX_STEPS",
    "check_setting",
    "simulate_batch",
    "inverse_batch",
    "stiffness",
    "weakest_direction",
    "deflection",
    "modes",
    "small_oscillations",
    "equilibrium",
    "state_space",
    "compliant_state_space",
    "simulate_flexible",
    "output_columns",
]

__version__: str
SINGULAR_TOL: float
JUMP_TOL: float
MIN_RTOL: float
MAX_STEPS: int

class PlanardynError(Exception): ...

class ModelError(PlanardynError, ValueError):
    source: str
    path: str

class ArgumentError(PlanardynError, ValueError):
    argument: str | None

class DataError(PlanardynError, ValueError):
    path: str | None

class AssemblyError(PlanardynError):
    residual: float
    iterations: int

class SingularityError(PlanardynError):
    kind: str
    sigma_min: float | None

class SimulationError(PlanardynError): ...

def check_setting(name: str, value: float) -> float: ...
def load(path: str | PathLike[str]) -> Mechanism: ...
def constraint_jacobian(mech: Mechanism, x: ArrayLike, scaled: bool = False) -> NDArray[np.float64]: ...
def loads(text: str, format: str = "yaml", source: str = "<string>") -> Mechanism: ...
def resolve_model(text: str, format: str = "yaml", source: str = "<string>") -> tuple[str, list[str]]: ...
def structure(mech: Mechanism, x: ArrayLike | None = None) -> dict[str, Any]: ...
def structure_of_model(text: str, source: str = "<dict>") -> dict[str, Any]: ...
def stiffness(
    mech: Mechanism,
    q: ArrayLike,
    body: str,
    point: str | None = None,
    wrench: ArrayLike | None = None,
    preload: dict[str, float] | None = None,
    gravity: bool = False,
) -> dict[str, Any]: ...
def weakest_direction(compliance: ArrayLike, length: float) -> tuple[NDArray[np.float64], float]: ...
def deflection(
    mech: Mechanism,
    q: ArrayLike,
    body: str,
    wrench: ArrayLike,
    point: str | None = None,
    steps: int = 10,
    preload: dict[str, float] | None = None,
    gravity: bool = False,
) -> dict[str, Any]: ...
def modes(mech: Mechanism, q: ArrayLike, free_rotors: bool = False, gravity: bool = False) -> dict[str, Any]: ...
def small_oscillations(mech: Mechanism, q: ArrayLike) -> dict[str, Any]: ...
def equilibrium(mech: Mechanism, q_start: ArrayLike) -> NDArray[np.float64]: ...
def simulate_flexible(
    mech: Mechanism,
    t_end: float,
    output_dt: float,
    method: str = "dop853",
    rtol: float = 1e-09,
    atol: float = 1e-12,
) -> dict[str, NDArray[np.float64]]: ...
def state_space(
    mech: Mechanism, q: ArrayLike, qd: ArrayLike, tau: ArrayLike, points: list[tuple[str, str]] = ...
) -> dict[str, NDArray[np.float64]]: ...
def compliant_state_space(
    mech: Mechanism, q: ArrayLike, points: list[tuple[str, str]] = ..., gravity: bool = False
) -> dict[str, NDArray[np.float64]]: ...
@final
class Mechanism:
    @property
    def name(self) -> str: ...
    @property
    def source(self) -> str: ...
    @property
    def warnings(self) -> list[str]: ...
    @property
    def dof(self) -> int: ...
    @property
    def n_bodies(self) -> int: ...
    @property
    def coordinate_names(self) -> list[str]: ...
    @property
    def coordinate_kinds(self) -> list[str]: ...
    @property
    def body_names(self) -> list[str]: ...
    @property
    def pair_names(self) -> list[str]: ...
    @property
    def point_names(self) -> list[str]: ...
    @property
    def ground_points(self) -> list[str]: ...
    @property
    def q0(self) -> NDArray[np.float64]: ...
    @property
    def qd0(self) -> NDArray[np.float64]: ...
    @property
    def drawn_q(self) -> NDArray[np.float64]: ...
    @property
    def x0(self) -> NDArray[np.float64]: ...
    @property
    def masses(self) -> NDArray[np.float64]: ...
    @property
    def inertias(self) -> NDArray[np.float64]: ...
    @property
    def scale(self) -> float: ...
    @property
    def gravity(self) -> NDArray[np.float64]: ...
    @property
    def body_points(self) -> list[list[tuple[str, tuple[float, float]]]]: ...
    @property
    def pairs(self) -> list[dict[str, Any]]: ...
    @property
    def simulate_defaults(self) -> dict[str, Any]: ...
    @property
    def actuators(self) -> list[dict[str, Any] | None]: ...
    def motor_torques(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        qdd: ArrayLike,
        tau: ArrayLike | None = None,
        x: ArrayLike | None = None,
        xd: ArrayLike | None = None,
        allow_singular: bool = False,
        recorded: bool = False,
    ) -> NDArray[np.float64]: ...
    def run_motor_torques(
        self,
        t: ArrayLike,
        q: ArrayLike,
        qd: ArrayLike,
        qdd: ArrayLike,
        tau: ArrayLike,
        x: ArrayLike,
        xd: ArrayLike,
    ) -> tuple[NDArray[np.float64], str | None]: ...
    @property
    def actuator_names(self) -> list[str]: ...
    @property
    def actuator_kinds(self) -> list[str]: ...
    def distribute_efforts(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        qdd: ArrayLike,
        method: str = "min_norm",
        preload: list[float] | None = None,
        x_start: ArrayLike | None = None,
    ) -> dict[str, NDArray[np.float64]]: ...
    def forward_dynamics_actuated(
        self, q: ArrayLike, qd: ArrayLike, efforts: ArrayLike, t: float = 0.0
    ) -> NDArray[np.float64]: ...
    def available_torque(self, coordinate: int, speed: ArrayLike) -> NDArray[np.float64] | None: ...
    def dissipated_power(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        qdd: ArrayLike,
        x: ArrayLike | None = None,
        xd: ArrayLike | None = None,
        allow_singular: bool = False,
    ) -> Any: ...
    def spec_json(self) -> str: ...
    def assemble(self, q: ArrayLike, x_start: ArrayLike | None = None) -> NDArray[np.float64]: ...
    def pair_geometry(self, x: ArrayLike) -> list[dict[str, Any]]: ...
    def point_positions(self, x: ArrayLike) -> NDArray[np.float64]: ...
    def kinematics(self, q: ArrayLike, qd: ArrayLike | None = None, x_start: ArrayLike | None = None) -> dict[str, Any]: ...
    def mass_matrix(
        self, q: ArrayLike, allow_singular: bool = False, x_start: ArrayLike | None = None
    ) -> NDArray[np.float64]: ...
    def forward_dynamics(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        t: float = 0.0,
        tau: ArrayLike | None = None,
        allow_singular: bool = False,
        x_start: ArrayLike | None = None,
    ) -> NDArray[np.float64]: ...
    def forward_dynamics_derivatives(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        t: float = 0.0,
        tau: ArrayLike | None = None,
        allow_singular: bool = False,
        x_start: ArrayLike | None = None,
    ) -> dict[str, NDArray[np.float64]]: ...
    def inverse_dynamics_derivatives(
        self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, allow_singular: bool = False
    ) -> dict[str, NDArray[np.float64]]: ...
    def inverse_dynamics(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        qdd: ArrayLike,
        x: ArrayLike | None = None,
        xd: ArrayLike | None = None,
        allow_singular: bool = False,
    ) -> NDArray[np.float64]: ...
    def reactions(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        t: float = 0.0,
        tau: ArrayLike | None = None,
        allow_singular: bool = False,
        x_start: ArrayLike | None = None,
    ) -> NDArray[np.float64]: ...
    def regressor(
        self,
        q: ArrayLike,
        qd: ArrayLike,
        qdd: ArrayLike,
        x: ArrayLike | None = None,
        xd: ArrayLike | None = None,
        allow_singular: bool = False,
    ) -> dict[str, NDArray[np.float64]]: ...
    @property
    def parameters(self) -> tuple[list[float], list[str]]: ...
    def along(
        self,
        t: ArrayLike,
        x: ArrayLike,
        q: ArrayLike,
        qd: ArrayLike,
        tau: ArrayLike,
        allow_singular: bool = False,
    ) -> dict[str, NDArray[np.float64]]: ...
    def point_motion(self, x: ArrayLike, xd: ArrayLike, xdd: ArrayLike) -> dict[str, Any]: ...
    def energy(self, q: ArrayLike, qd: ArrayLike, x_start: ArrayLike | None = None) -> tuple[float, float]: ...
    def simulate(
        self,
        t_end: float | None = None,
        method: str | None = None,
        rtol: float | None = None,
        atol: float | None = None,
        dt: float | None = None,
        t_eval: ArrayLike | None = None,
        output_dt: float | None = None,
        q0: ArrayLike | None = None,
        qd0: ArrayLike | None = None,
        drives: Callable[[float, NDArray[np.float64], NDArray[np.float64]], ArrayLike] | None = None,
        progress: Callable[[float], Any] | None = None,
        max_steps: int | None = None,
        motion: list[tuple[int, float | tuple[list[float], list[float]] | Callable[[float], Any]]] | None = None,
        events: list[tuple[Any, ...]] = ...,
        dense_output: bool = False,
    ) -> Run: ...

@final
class Run:
    def __getitem__(self, key: str, /) -> Any: ...
    def get(self, key: str, default: Any = None) -> Any: ...
    def __contains__(self, key: str, /) -> bool: ...

@final
class DenseOutput:
    def __call__(self, t: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...
    @property
    def t_min(self) -> float: ...
    @property
    def t_max(self) -> float: ...
    @property
    def steps(self) -> int: ...

@final
class Effector:
    def __new__(cls, mech: Mechanism, point: str, body: str | None = None) -> Effector: ...
    @property
    def body(self) -> str: ...
    @property
    def dim(self) -> int: ...
    def state(self, q: ArrayLike, x_start: ArrayLike | None = None) -> dict[str, Any]: ...
    def pose(self, x: ArrayLike) -> NDArray[np.float64]: ...
    def jacobian(self, x: ArrayLike) -> NDArray[np.float64]: ...
    def convective(self, x: ArrayLike, qd: ArrayLike) -> NDArray[np.float64]: ...
    def measures(self, jt: ArrayLike) -> tuple[float, float]: ...
    def solve(self, target: ArrayLike, q_guess: ArrayLike, x_start: ArrayLike | None = None) -> dict[str, Any]: ...
    def reach(
        self, target: ArrayLike, q_start: ArrayLike | None = None, x_start: ArrayLike | None = None
    ) -> dict[str, Any]: ...
    def motion(
        self,
        t: ArrayLike,
        x: ArrayLike,
        xd: ArrayLike,
        xdd: ArrayLike,
        q_start: ArrayLike | None = None,
        singular_tol: float = ...,
    ) -> dict[str, Any]: ...

def output_columns() -> list[tuple[str, str, str, str, str]]: ...
def simulate_batch(
    variants: list[tuple[Mechanism, dict[str, Any]]],
    threads: int | None = None,
    finish: Callable[[int, dict[str, Any]], Any] | None = None,
) -> list[Any]: ...
def inverse_batch(
    variants: list[tuple[Mechanism, dict[str, Any]]],
    threads: int | None = None,
    finish: Callable[[int, dict[str, Any]], Any] | None = None,
) -> list[Any]: ...
