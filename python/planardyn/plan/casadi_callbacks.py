"""CasADi callbacks of planardyn's functions with exact Jacobians, for IPOPT.

f and its Jacobian are planardyn's (e.g. Mechanism.forward_dynamics and the exact
forward_dynamics_derivatives), each one casadi.Callback whose Jacobian is another Callback.
An evaluation the kinematics refuse (a singularity, out of reach, coordinates too far from
the drawing) gives NaN, after which IPOPT shortens its step; the solution never holds one
(collocation checks).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._core import AssemblyError, SingularityError

FloatArray = NDArray[np.float64]


def callback(ca: Any, name: str, sizes: Sequence[int], n_out: int, value: Callable[..., FloatArray],
             jacobian: Callable[..., Sequence[FloatArray]], keep: list[Any]) -> Any:
    """A casadi.Callback y = value(*args) whose Jacobian is another Callback, jacobian(*args)
    giving dy/d(each arg). ``keep`` holds both alive while the solver uses them."""
    n_in = len(sizes)

    class Jacobian(ca.Callback):
        def __init__(self, jname: str, opts: dict[str, Any]) -> None:
            ca.Callback.__init__(self)
            self.construct(jname, opts)

        def get_n_in(self) -> int:
            return n_in + 1

        def get_n_out(self) -> int:
            return n_in

        def get_sparsity_in(self, i: int) -> Any:
            return ca.Sparsity.dense(sizes[i], 1) if i < n_in else ca.Sparsity(n_out, 1)

        def get_sparsity_out(self, i: int) -> Any:
            return ca.Sparsity.dense(n_out, sizes[i])

        def eval(self, arg: list[Any]) -> list[Any]:
            return [ca.DM(j) for j in jacobian(*(np.asarray(a, dtype=float).ravel() for a in arg[:n_in]))]

    class Function(ca.Callback):
        def __init__(self) -> None:
            ca.Callback.__init__(self)
            self.construct(name, {"enable_fd": False})

        def get_n_in(self) -> int:
            return n_in

        def get_n_out(self) -> int:
            return 1

        def get_sparsity_in(self, i: int) -> Any:
            return ca.Sparsity.dense(sizes[i], 1)

        def get_sparsity_out(self, i: int) -> Any:
            return ca.Sparsity.dense(n_out, 1)

        def eval(self, arg: list[Any]) -> list[Any]:
            return [ca.DM(value(*(np.asarray(a, dtype=float).ravel() for a in arg)))]

        def has_jacobian(self) -> bool:
            return True

        def get_jacobian(self, jname: str, inames: Any, onames: Any, opts: dict[str, Any]) -> Any:
            jac = Jacobian(jname, opts)
            keep.append(jac)
            return jac

    f = Function()
    keep.append(f)
    return f


def or_nan(shapes: Sequence[tuple[int, ...]]) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Evaluations the kinematics refuse give NaN (see the module)."""

    def wrap(fn: Callable[..., Any]) -> Callable[..., Any]:
        def safe(*args: FloatArray) -> Any:
            try:
                return fn(*args)
            except (SingularityError, AssemblyError, ValueError):
                nan = [np.full(s, np.nan) for s in shapes]
                return nan[0] if len(nan) == 1 else nan

        return safe

    return wrap
