"""Identification of a built mechanism's inertial parameters: which combinations of them the
drive efforts can tell apart (the base parameters).

The efforts are linear in the inertial parameters pi (``Mechanism.regressor``:
tau = Y pi + tau_o), but some parameters act only in fixed combinations (a link's mass moved
along a ground pivot's axis, the masses of two bodies joined at a point...), so only r of the
p columns of Y are independent. :func:`base_parameters` finds them numerically, by QR with
column pivoting of Y stacked over many states, and writes each base parameter as a named
linear combination of the physical ones.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .mechanism import Mechanism

FloatArray = NDArray[np.float64]

#: A pivot of the QR factor below this fraction of the largest is a dependent column: the
#: columns are scaled to unit norm first, so this is a relative singular-value-like bound,
#: far above round-off (~1e-14 for these sums) and far below any physical effect.
RANK_RTOL = 1e-9
#: Coefficients of a combination smaller than this are round-off of an exact zero.
COEFFICIENT_TOL = 1e-9


@dataclass(frozen=True)
class BaseParameters:
    """The identifiable combinations of the inertial parameters.

    ``beta = pi[independent] + K @ pi[dependent]``, and for every state
    ``Y @ pi == Y[..., independent] @ beta``. ``names[k]`` and ``expressions[k]`` describe
    ``beta[k]``.
    """

    #: All parameter names (the columns of Y).
    parameters: list[str]
    #: Indices of the base parameters' own columns, and of the columns folded into them.
    independent: list[int]
    dependent: list[int]
    #: (r, p - r): how the dependent parameters add to each base parameter.
    K: FloatArray
    #: Samples the rank was found from, and the condition number of the scaled base columns.
    samples: int
    condition: float

    @property
    def rank(self) -> int:
        return len(self.independent)

    @property
    def names(self) -> list[str]:
        return [self.parameters[i] for i in self.independent]

    @property
    def expressions(self) -> list[str]:
        """Each base parameter as text, e.g. ``I_crank + 0.09 m_coupler``."""
        out = []
        for k, i in enumerate(self.independent):
            terms = [self.parameters[i]]
            for c, j in zip(self.K[k], self.dependent):
                if abs(c) > COEFFICIENT_TOL:
                    terms.append(f"{'-' if c < 0 else '+'} {abs(c):.6g} {self.parameters[j]}")
            out.append(" ".join(terms))
        return out

    def of(self, pi: FloatArray | dict[str, float]) -> FloatArray:
        """The base parameters of a full parameter vector (or dict by name)."""
        p = np.array([pi[n] for n in self.parameters]) if isinstance(pi, dict) else np.asarray(pi, float)
        return p[self.independent] + self.K @ p[self.dependent]


def sample_states(mech: Mechanism, n: int = 200, seed: int = 0) -> tuple[FloatArray, ...]:
    """``n`` states (q, qd, qdd, x) of one assembly branch: a random walk in q from the
    model's start (steps of 0.1 rad, or 0.1 of the drawing's size for a displacement), each
    step continued from the last and kept only where the mechanism assembles; rates and
    accelerations drawn from a standard normal (any values serve: Y is linear in them)."""
    rng = np.random.default_rng(seed)
    scale = np.array([0.1 if k == "angle" else 0.1 * mech.scale for k in mech.coordinate_kinds])
    q, x = np.array(mech.q0, float), mech.assemble(mech.q0)
    qs: list[FloatArray] = []
    xs: list[FloatArray] = []
    for _ in range(20 * n):
        if len(qs) == n:
            break
        step = q + scale * rng.standard_normal(mech.dof)
        try:
            x = mech.assemble(step, x_start=x)
        except Exception:  # noqa: BLE001 - outside the workspace: try another step
            continue
        q = step
        qs.append(q)
        xs.append(x)
    if len(qs) < n:
        raise ValueError(f"only {len(qs)} of {n} random states assembled; the mechanism hardly moves from its start")
    shape = (n, mech.dof)
    return np.array(qs), rng.standard_normal(shape), rng.standard_normal(shape), np.array(xs)


def base_parameters(mech: Mechanism, samples: int = 200, seed: int = 0) -> BaseParameters:
    """The base parameters of ``mech``, from Y at ``samples`` random states
    (:func:`sample_states`), by QR with column pivoting (scipy)."""
    from scipy.linalg import qr

    q, qd, qdd, x = sample_states(mech, samples, seed)
    Y, _ = mech.regressor(q, qd, qdd, x=x)
    W = Y.reshape(-1, Y.shape[-1])
    norms = np.linalg.norm(W, axis=0)
    live = norms > 0.0
    scaled = W[:, live] / norms[live]
    _, R, perm = qr(scaled, mode="economic", pivoting=True)
    diag = np.abs(np.diag(R))
    r = int(np.sum(diag > RANK_RTOL * diag[0]))
    cols = np.flatnonzero(live)[perm]
    independent, dependent = cols[:r], np.concatenate([cols[r:], np.flatnonzero(~live)])
    # W[:, dep] = W[:, ind] @ K (least squares, exact up to round-off for dependent columns).
    K = np.zeros((r, 0))
    if len(dependent):
        K = np.asarray(np.linalg.lstsq(W[:, independent], W[:, dependent], rcond=None)[0], dtype=np.float64)
    condition = float(np.linalg.cond(scaled[:, perm[:r]]))
    names = list(mech.inertial_parameters)
    return BaseParameters(names, independent.tolist(), dependent.tolist(), K, samples, condition)
