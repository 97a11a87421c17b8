"""Sensitivities to design parameters by central differences, all perturbed designs run as
one batch (:mod:`planardyn.batch`, Rust threads or an executor).

A *design* is a function of named parameters: dotted paths into a model dict (as
:func:`planardyn.batch.sweep` takes: ``"bodies.crank.mass"``, ``"points.B.0"``), or the
keyword arguments of a model constructor such as :func:`planardyn.library.five_bar_model`
(``"proximal"``, ``"distal"``). Three quantities:

- :func:`trajectory`: d q(t) / dp of a simulation (or any function of its result);
- :func:`efforts`: d tau(t) / dp of the drive efforts along an end-effector path (the
  inverse kinematics solved again for every design);
- :func:`objective`: d f / dp of a function of that motion, e.g. :func:`peak_effort`.

Scheme (docs/sensitivity.md): for parameter p_i of value v_i, the step is
``h_i = rel_step * max(|v_i|, typical_i)`` rounded so that v_i + h_i - v_i == h_i exactly,
with ``rel_step = eps^(1/3)`` (6.1e-6) by default: it balances the truncation error of the
central difference, f''' h^2 / 6, against the rounding error eps |f| / h. The derivative is

    D(h) = (f(v + h e_i) - f(v - h e_i)) / (2 h),

and the error estimate is Richardson's |D(h) - D(2h)| / 3 (D(h) = f' + c h^2 + O(h^4), so
D(2h) - D(h) = 3 c h^2): 4p + 1 evaluations in one batch.
"""

from __future__ import annotations

import builtins
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import batch
from ._core import AssemblyError, ModelError, PlanardynError, SimulationError, SingularityError
from .arguments import error
from .mechanism import Mechanism
from .notebook import Summarized

__all__ = ["Sensitivity", "efforts", "objective", "peak_effort", "rms_effort", "trajectory", "DEFAULT_REL_STEP"]

#: The exceptions a failed variant re-raises, by the name its BatchError records.
_ERRORS = {e.__name__: e for e in (AssemblyError, ModelError, PlanardynError, SimulationError, SingularityError)}

FloatArray = NDArray[np.float64]
#: A model with dotted-path parameters, or a constructor ``make(**params)`` of a model.
Design = Mechanism | Mapping[str, Any] | Callable[..., Mechanism | Mapping[str, Any]]

#: eps^(1/3): the relative step that balances truncation (h^2) and rounding (eps / h) errors.
DEFAULT_REL_STEP = float(np.finfo(float).eps ** (1.0 / 3.0))


@dataclass(frozen=True, repr=False)
class Sensitivity(Summarized):
    """Derivatives of a quantity (shape S) with respect to p named parameters.

    ``value`` (S) at the nominal design; ``derivative`` and ``error`` (p, *S): the central
    difference D(h) and its Richardson error estimate |D(h) - D(2h)| / 3, in the units of
    the quantity per unit of each parameter; ``values`` and ``steps`` (p,) the nominal
    parameter values and the steps h used.
    """

    names: list[str]
    values: FloatArray
    steps: FloatArray
    value: FloatArray
    derivative: FloatArray
    error: FloatArray

    def __getitem__(self, name: str) -> FloatArray:
        """The derivative with respect to one parameter (shape S)."""
        return self.derivative[self.names.index(name)]

    def __repr__(self) -> str:
        return (f"Sensitivity(d{list(self.value.shape) if self.value.ndim else ' value'} / d({', '.join(self.names)}), "
                f"largest error estimate {float(np.max(self.error, initial=0.0)):.2g})")

    def _summary_rows(self) -> list[tuple[str, str]]:
        return [("quantity", f"shape {self.value.shape}" if self.value.ndim else f"{float(self.value):.6g}"),
                ("parameters", ", ".join(self.names))]

    def _summary_tables(self) -> list[tuple[list[str], list[list[str]]]]:
        rows = []
        for k, name in enumerate(self.names):
            d, e = self.derivative[k], self.error[k]
            big = int(np.argmax(np.abs(d))) if d.ndim else 0
            rows.append([name, f"{self.values[k]:.6g}", f"{self.steps[k]:.3g}", f"{np.ravel(d)[big]:.6g}",
                         f"{np.ravel(e)[big]:.2g}"])
        entry = "derivative" if self.value.ndim == 0 else "derivative (largest entry)"
        return [(["parameter", "value", "step", entry, "error"], rows)]

    def __str__(self) -> str:
        rows = [f"{'parameter':>32} {'value':>12} {'step':>10} {'derivative':>14} {'error':>10}"]
        for k, name in enumerate(self.names):
            d, e = self.derivative[k], self.error[k]
            big = int(np.argmax(np.abs(d))) if d.ndim else 0
            rows.append(f"{name:>32} {self.values[k]:>12.6g} {self.steps[k]:>10.3g} {np.ravel(d)[big]:>14.6g} "
                        f"{np.ravel(e)[big]:>10.2g}" + ("" if d.ndim == 0 else "  (largest entry)"))
        return "\n".join(rows)


# ---------------------------------------------------------------------- the scheme


def _nominal(design: Design, params: Mapping[str, float] | Sequence[str]) -> tuple[list[str], FloatArray]:
    if isinstance(params, Mapping):
        return list(params), np.array([float(v) for v in params.values()])
    if callable(design) and not isinstance(design, Mechanism):
        raise error("params", "with a model constructor, give the parameters as a mapping {name: nominal value}")
    model = design.to_dict() if isinstance(design, Mechanism) else design
    return list(params), np.array([_read(model, p) for p in params])


def _read(model: Mapping[str, Any], path: str) -> float:
    node: Any = model
    for key in path.split("."):
        node = batch._child(node, key, path)
    if not isinstance(node, (int, float)):
        raise error("params", f"{path}: expected a number in the model, found {node!r}; give its value in params")
    return float(node)


def _model(design: Design, names: list[str], values: FloatArray) -> Mechanism | dict[str, Any]:
    if callable(design) and not isinstance(design, Mechanism):
        made = design(**{n: float(v) for n, v in zip(names, values)})
        return made if isinstance(made, Mechanism) else dict(made)
    model = design.to_dict() if isinstance(design, Mechanism) else dict(design)
    for n, v in zip(names, values):
        model = batch._set(model, n, float(v))
    return model


def steps(values: ArrayLike, rel_step: float = DEFAULT_REL_STEP, typical: ArrayLike | float = 0.0,
          names: Sequence[str] | None = None) -> FloatArray:
    """The steps h_i = rel_step max(|v_i|, typical_i), rounded so that (v + h) - v == h.

    ``typical`` (scalar or (p,), in each parameter's units) is a floor for parameters whose
    value is 0 or near it (a point on an axis): their step is then relative to it.
    """
    v = np.asarray(values, dtype=float)
    h = rel_step * np.maximum(np.abs(v), np.broadcast_to(np.asarray(typical, dtype=float), v.shape))
    h = (v + h) - v
    bad = np.flatnonzero(~(h > 0) | ~np.isfinite(h))
    if len(bad):
        which = names[bad[0]] if names is not None else f"parameter {bad[0]}"
        raise error("typical", f"{which} = {v[bad[0]]:g}: no step can be made from it; give typical= (a typical "
                         f"magnitude in its units, e.g. the mechanism's size for a coordinate that is 0)")
    return h


def _differences(design: Design, params: Mapping[str, float] | Sequence[str],
                 run: Callable[[list[Any]], list[Any]], quantity: Callable[[Any], ArrayLike],
                 rel_step: float, typical: ArrayLike | float) -> Sensitivity:
    """Evaluate the nominal design and v +- h e_i, v +- 2h e_i for every i in one batch."""
    names, v = _nominal(design, params)
    h = steps(v, rel_step, typical, names)
    shifts = [np.zeros_like(v)] + [s * h[i] * np.eye(len(v))[i] for i in range(len(v)) for s in (1, -1, 2, -2)]
    def where(k: int) -> str:
        return "the nominal design" if k == 0 else f"{names[(k - 1) // 4]} = {(v + shifts[k])[(k - 1) // 4]:.9g}"

    models = []
    for k, d in enumerate(shifts):
        try:
            models.append(_model(design, names, v + d))
        except Exception as e:
            raise type(e)(f"sensitivity: {where(k)}: {e}") from e
    results = run(models)
    for k, r in enumerate(results):
        if isinstance(r, batch.BatchError):
            exc: type[Exception] = _ERRORS[r.type] if r.type in _ERRORS else getattr(builtins, r.type, PlanardynError)
            raise exc(f"sensitivity: {where(k)}: {r.message}")
    f = np.array([np.asarray(quantity(r), dtype=float) for r in results])
    plus, minus, plus2, minus2 = (f[1 + j::4] for j in range(4))
    shape = (len(v),) + (1,) * (f.ndim - 1)
    d1 = (plus - minus) / (2 * h.reshape(shape))
    d2 = (plus2 - minus2) / (4 * h.reshape(shape))
    return Sensitivity(names, v, h, f[0], d1, np.abs(d1 - d2) / 3)


# ---------------------------------------------------------------------- the quantities


def trajectory(design: Design, params: Mapping[str, float] | Sequence[str], t_eval: ArrayLike, *,
               quantity: Callable[[Any], ArrayLike] | None = None, rel_step: float = DEFAULT_REL_STEP,
               typical: ArrayLike | float = 0.0, threads: int | None = None, executor: Any = None,
               **settings: Any) -> Sensitivity:
    """d q(t) / dp of a simulation with the model's drives, at the times ``t_eval`` (s).

    Parameters
    ----------
    design : Mechanism, model dict or callable
        With dotted-path parameters, or a constructor called as ``design(**params)``.
    params : mapping or sequence of str
        ``{name: nominal value}``, or (for a model) the dotted paths, values read from it.
    t_eval : (N,) array_like
        Output times (s); the run ends at the last.
    quantity : callable, optional
        ``f(result) -> array`` of a :class:`SimulationResult`; default ``result.q`` (N, m).
    rel_step, typical
        The step rule (module docs); ``typical`` (scalar or (p,)) stands in for |v| near 0.
        An adaptive integrator's step choices change with p too: use rtol near 1e-12 or a
        fixed-step method, and check ``error``.
    settings
        ``method``, ``rtol``, ``atol``, ``dt``, ``q0``, ``qd0``... as for
        :func:`planardyn.batch.simulate`.
    """
    t_eval = np.asarray(t_eval, dtype=float)

    own: dict[str, Any] = {k: settings.pop(k) for k in ("q0", "qd0") if k in settings}

    def run(models: list[Any]) -> list[Any]:
        out = batch.simulate([(m, own) for m in models], float(t_eval[-1]), t_eval=t_eval, threads=threads,
                             executor=executor, **settings)
        return [r if isinstance(r, batch.BatchError) or r.success else
                batch.BatchError(k, "SimulationError", f"the run stopped at t = {r.t[-1]:.4g} s: {r.message}")
                for k, r in enumerate(out)]

    return _differences(design, params, run, quantity or (lambda r: r.q), rel_step, typical)


def objective(design: Design, params: Mapping[str, float] | Sequence[str], path: Any,
              quantity: Callable[[Any], ArrayLike], *, rel_step: float = DEFAULT_REL_STEP,
              typical: ArrayLike | float = 0.0, threads: int | None = None, executor: Any = None,
              **motion: Any) -> Sensitivity:
    """d f / dp of ``quantity(motion)`` for the end-effector ``path`` solved on every design.

    ``quantity`` takes a :class:`planardyn.robot.TaskMotion` (``tau``, ``q``, ``sigma_I``...)
    and returns a number or an array (e.g. ``[peak_effort(m), m.sigma_II.min()]``);
    ``motion`` goes to :func:`planardyn.batch.inverse_dynamics` (``point``, ``dt``, ``n``,
    ``q_start``, ``singular_tol``). The samples are the same for every design, so their
    efforts can be differenced. A design on which the path meets a singularity or leaves
    the reach raises that error, naming the parameter.
    """
    def run(models: list[Any]) -> list[Any]:
        return batch.inverse_dynamics(models, path, threads=threads, executor=executor, **motion)

    return _differences(design, params, run, quantity, rel_step, typical)


def efforts(design: Design, params: Mapping[str, float] | Sequence[str], path: Any, **options: Any) -> Sensitivity:
    """d tau(t) / dp (p, N, m) of the drive efforts along ``path`` (N m or N per unit of each
    parameter); options as for :func:`objective`."""
    return objective(design, params, path, lambda m: m.tau, **options)


def peak_effort(motion: Any, drive: int | None = None) -> float:
    """Largest |tau| over the samples, of one drive or of all (N m or N)."""
    tau = np.abs(motion.tau if drive is None else motion.tau[:, drive])
    return float(tau.max())


def rms_effort(motion: Any, drive: int | None = None) -> float:
    """Root mean square of tau over the motion's duration (trapezoidal rule), of one drive
    or of all together (sqrt of the mean of sum_k tau_k^2) (N m or N)."""
    tau = motion.tau if drive is None else motion.tau[:, [drive]]
    y2 = np.sum(tau**2, axis=1)
    t = motion.t
    return math.sqrt(float(np.sum(0.5 * (y2[1:] + y2[:-1]) * np.diff(t))) / (t[-1] - t[0]))
