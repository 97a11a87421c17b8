"""Identification of a built mechanism's inertial and loss parameters: which combinations of
them the drive efforts can tell apart (the base parameters), and their estimates.

The efforts are linear in the parameters pi (``Mechanism.regressor``: tau = Y pi + tau_o;
the bodies' inertial parameters, then the rotors' inertias and the friction coefficients,
``Mechanism.regressor_parameters``), but some parameters act only in fixed combinations (a
link's mass moved along a ground pivot's axis, the masses of two bodies joined at a point, a
rotor's inertia and that of the crank it turns...), so only r of the p columns of Y are
independent. :func:`base_parameters` finds them numerically, by QR with
column pivoting of Y stacked over many states, and writes each base parameter as a named
linear combination of the physical ones.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._core import PlanardynError
from .arguments import array, count, data_error, error, finite_rates, limits, positive, rates_overflow, samples, times
from .mechanism import Mechanism
from .notebook import Summarized

FloatArray = NDArray[np.float64]

#: A pivot of the QR factor below this fraction of the largest is a dependent column: the
#: columns are scaled to unit norm first, so this is a relative singular-value-like bound,
#: far above round-off (~1e-14 for these sums) and far below any physical effect.
RANK_RTOL = 1e-9
#: Coefficients of a combination smaller than this are round-off of an exact zero.
COEFFICIENT_TOL = 1e-9
#: Most random states a search for the base parameters (or an excitation) takes: far more
#: than the rank needs, and about 1 GB of regressor rows for the largest shipped model.
MAX_SAMPLES = 10**5
#: The excitation's cost of a motion out of reach, unassembled or near a singularity: far
#: above any condition number, and finite, which Powell's line searches need.
INFEASIBLE = 1e12
#: A coordinate's residual below this fraction of the efforts' RMS is round-off (data
#: without noise): its weight in the second pass is capped there instead of growing without
#: bound (an exact zero would make it infinite and the estimate NaN).
RESIDUAL_FLOOR = 1e-12
#: A motion this many times past its limits is as bad as any: the excitation's cost of a
#: larger excess (or an infinite one) is that of this one.
EXCESS_CAP = 1e6
#: Most harmonics of an excitation: its reach is checked on 1000 points per harmonic, and
#: Powell's search has 2 m harmonics coefficients to tune; beyond a few tens neither pays.
MAX_HARMONICS = 50
#: The low-pass filter's order (Butterworth, run forwards and backwards).
FILTER_ORDER = 4
#: Fewest rows the zero-phase filter can run on: scipy's ``sosfiltfilt`` pads each end with
#: 3 (2 sections + 1) samples (its default ``padlen`` for ``FILTER_ORDER // 2`` sections) and
#: needs more rows than that.
MIN_FILTER_ROWS = 3 * (2 * (FILTER_ORDER // 2) + 1) + 1
#: Lowest cutoff over half the sampling rate: the sections' denominators differ from a double
#: pole at 1 by about (pi cutoff / (fs / 2))^2, which below this nears round-off (the
#: filter's start-up solve turns singular; measured: the output drifts by 1e-4 at 1e-7 and
#: 10 % at 1e-8, and scipy raises at 1e-300).
MIN_CUTOFF_RATIO = 1e-6


@dataclass(frozen=True, repr=False)
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

    def __repr__(self) -> str:
        return (f"BaseParameters({self.rank} of {len(self.parameters)} parameters identifiable, condition "
                f"{self.condition:.3g}, from {self.samples} samples)")

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

    def of(self, pi: ArrayLike | dict[str, float]) -> FloatArray:
        """The base parameters of a full parameter vector (or dict by name)."""
        if isinstance(pi, dict):
            missing = [n for n in self.parameters if n not in pi]
            if missing:
                raise error("pi", f"pi has no value for {', '.join(missing)}: give every parameter by name "
                                  "(Mechanism.regressor_parameters lists them)")
            pi = [pi[n] for n in self.parameters]
        p = array("pi", pi, shape=(len(self.parameters),), what="one value per parameter")
        beta = p[self.independent] + self.K @ p[self.dependent]
        if not np.isfinite(beta).all():
            raise error("pi", f"pi's values (largest {np.abs(p).max():.3g}) overflow in the base parameters' sums: "
                              "give them in SI units of a physical size")
        return beta


def sample_states(mech: Mechanism, n: int = 200, seed: int = 0) -> tuple[FloatArray, ...]:
    """``n`` states (q, qd, qdd, x) of one assembly branch: a random walk in q from the
    model's start (steps of 0.1 rad, or 0.1 of the drawing's size for a displacement), each
    step continued from the last and kept only where the mechanism assembles; rates and
    accelerations drawn from a standard normal (any values serve: Y is linear in them)."""
    n = count("n", n, 1, MAX_SAMPLES)
    rng = np.random.default_rng(count("seed", seed, 0, 2**64 - 1))
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
        except PlanardynError:  # outside the workspace (or past the loader's bounds): try another step
            continue
        q = step
        qs.append(q)
        xs.append(x)
    if len(qs) < n:
        raise PlanardynError(f"only {len(qs)} of {n} random states assembled; the mechanism hardly moves from its "
                             "start")
    shape = (n, mech.dof)
    return np.array(qs), rng.standard_normal(shape), rng.standard_normal(shape), np.array(xs)


def base_parameters(mech: Mechanism, samples: int = 200, seed: int = 0) -> BaseParameters:
    """The base parameters of ``mech``, from Y at ``samples`` random states
    (:func:`sample_states`), by QR with column pivoting (scipy)."""
    from scipy.linalg import qr

    p = len(mech.regressor_parameters)
    least = math.ceil(p / mech.dof)
    samples = count("samples", samples, least, MAX_SAMPLES)  # m rows each: at least p rows to find the rank
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
    names = list(mech.regressor_parameters)
    return BaseParameters(names, independent.tolist(), dependent.tolist(), K, samples, condition)


@dataclass(frozen=True, repr=False)
class Identification(Summarized):
    """Base parameters estimated from a measured motion (:func:`identify`).

    ``beta`` with ``std_error`` (one standard deviation, from the residuals' variance per
    coordinate), ``prior`` the base parameters of the model identified against; ``pi`` a
    full parameter vector with the estimated base parameters that is physically consistent
    (positive masses, positive inertia about every centre of mass), nearest the model's.
    """

    base: BaseParameters
    beta: FloatArray
    std_error: FloatArray
    prior: FloatArray
    pi: dict[str, float]
    #: RMS of the efforts' residual per coordinate (N m or N), and the samples used.
    residual_rms: FloatArray
    samples: int

    def __repr__(self) -> str:
        rms = ", ".join(f"{v:.3g}" for v in self.residual_rms)
        return (f"Identification({self.base.rank} base parameters from {self.samples} samples, "
                f"residual RMS per coordinate [{rms}])")

    def _summary_rows(self) -> list[tuple[str, str]]:
        return [("samples", f"{self.samples}"), ("base parameters", f"{self.base.rank} of {len(self.base.parameters)}"),
                ("condition", f"{self.base.condition:.3g}"),
                ("residual RMS", ", ".join(f"{v:.3g}" for v in self.residual_rms) + " (N m or N, per coordinate)")]

    def _summary_tables(self) -> list[tuple[list[str], list[list[str]]]]:
        rows = [[e, f"{b:.6g}", f"{s:.3g}", f"{p:.6g}"]
                for e, b, s, p in zip(self.base.expressions, self.beta, self.std_error, self.prior)]
        return [(["base parameter", "identified", "std error", "prior"], rows)]

    def report(self) -> str:
        """A table: each base parameter, identified ± standard error, and the prior."""
        lines = [f"{'base parameter':<60} {'identified':>12} {'std error':>10} {'prior':>12}"]
        for e, b, s, p in zip(self.base.expressions, self.beta, self.std_error, self.prior):
            lines.append(f"{e[:60]:<60} {b:12.6g} {s:10.3g} {p:12.6g}")
        rms = ", ".join(f"{v:.3g}" for v in self.residual_rms)
        lines.append(f"{self.samples} samples; residual RMS per coordinate: {rms}")
        return "\n".join(lines)


def identify(
    mech: Mechanism,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    tau: ArrayLike,
    x: ArrayLike | None = None,
    base: BaseParameters | None = None,
) -> Identification:
    """Estimate the base parameters from a motion's rows (q, qd, qdd, measured efforts tau;
    (N, m) each; x the body coordinates of the branch, as for ``inverse_dynamics``).

    Weighted least squares (two passes: ordinary least squares, then each coordinate's rows
    weighted by the inverse of its residual's standard deviation), with standard errors from
    the weighted residual's variance. Then the physically consistent full parameters nearest
    the model's that have those base parameters (scipy's SLSQP: m > 0 and m I_O - (m cx)^2 -
    (m cy)^2 > 0, i.e. a positive inertia about the centre of mass; rotor inertias and
    friction coefficients >= 0).

    With actuators the measured efforts of their coordinates are the motor torques (a
    simulation's ``tau_motor``, ``Mechanism.motor_torques``): the rotor's torque J omega_r'
    (its ``J_`` column) and the motor friction before the gear, the joint-side row through it.
    Two terms are taken from the model (docs/identification.md, *Losses*): a transmission's
    branch (motoring or back-driven, when its efficiencies are below 1) and the pin friction's
    load, the reaction, which the ``mu_``
    columns multiply. Both are exact when the model is near the robot; where the robot's
    loads differ from the model's by d, the pin friction is off by d of itself. The loads
    are not re-evaluated from the estimate: they depend on parameters the efforts do not
    determine (not only on the base parameters).

    Rates and accelerations from measured positions: differentiate a low-pass filtered q,
    e.g. :func:`differentiate`, and filter tau with the same filter.

    Raises
    ------
    ArgumentError
        An argument of the wrong shape, or a NaN or an infinity in it (named by row and
        column), found before any computation.
    DataError
        Rows that cannot identify the base parameters: fewer rows than the parameters need
        (the message gives the least number), or a motion along which some base parameters
        act not at all or only together with others (a robot held still, a coordinate that
        does not move): the message names them.
    """
    base = _base_of(mech, base)
    m = mech.dof
    names = mech.coordinate_names
    q = array("q", q, ndim=2, what="rows of coordinates, rad or m")
    n = len(q)
    q, qd, qdd, tau = (samples(k, v, n, m, columns=[f"{prefix}{c}" for c in names]) for k, v, prefix in
                       (("q", q, ""), ("qd", qd, "qd_"), ("qdd", qdd, "qdd_"), ("tau", tau, "tau_")))
    Y, tau_o = mech.regressor(q, qd, qdd, x=x)
    Wb = Y[..., base.independent]  # (N, m, r)
    rhs = tau - tau_o
    r = base.rank
    _check_identifiable(base, Wb.reshape(-1, r), n, m)
    beta, _ = _least_squares(Wb.reshape(-1, r), rhs.reshape(-1))
    _refuse_overflow(tau, beta, Wb @ beta)  # the second pass's weights come from these residuals
    # Second pass: each coordinate's rows weighted by the inverse of its residual's size.
    floor = RESIDUAL_FLOOR * max(float(np.sqrt(np.mean(rhs**2))), np.finfo(float).tiny)
    sigma = np.maximum(np.sqrt(np.mean((rhs - Wb @ beta) ** 2, axis=0)), floor)  # per coordinate
    Ww, rw = (Wb / sigma[None, :, None]).reshape(-1, r), (rhs / sigma).reshape(-1)
    beta, variance = _least_squares(Ww, rw)
    s2 = float(np.sum((rw - Ww @ beta) ** 2) / (n * m - r))
    std = np.sqrt(s2 * variance)
    _refuse_overflow(tau, beta, std)
    prior_pi = np.array(list(mech.regressor_parameters.values()))
    resid = np.sqrt(np.mean((rhs - Wb @ beta) ** 2, axis=0))
    pi = _consistent(base, beta, prior_pi, mech.n_bodies)
    return Identification(base, beta, std, base.of(prior_pi), dict(zip(base.parameters, pi)), resid, n)


def _refuse_overflow(tau: FloatArray, *values: FloatArray) -> None:
    """Refuse efforts so large that a least-squares pass's values overflow (1e308 in one row:
    a NaN residual, on which the second pass's SVD fails)."""
    if not all(np.isfinite(v).all() for v in values):
        raise error("tau", f"tau: the efforts (largest {np.abs(tau).max():.3g}) overflow the least-squares sums: "
                           "give them in N m or N")


def _base_of(mech: Mechanism, base: BaseParameters | None) -> BaseParameters:
    """``base``, or the mechanism's found anew; one of another mechanism is refused."""
    if base is None:
        return base_parameters(mech)
    if not isinstance(base, BaseParameters):
        raise TypeError(f"base must be a BaseParameters (identify.base_parameters), not {type(base).__name__}")
    if base.parameters != list(mech.regressor_parameters):
        raise error("base", "base holds the base parameters of another mechanism (its parameters differ): "
                            "use identify.base_parameters(mech) of this one")
    return base


def _check_identifiable(base: BaseParameters, W: FloatArray, n: int, m: int) -> None:
    """Refuse rows W (n m, r) that cannot determine the r base parameters: too few, or some
    of them not excited (their columns zero, or combinations of the others, here)."""
    from scipy.linalg import qr

    r = base.rank
    if n * m <= r:
        raise data_error(None, f"{n} rows of {m} efforts cannot determine {r} base parameters (and their "
                               f"errors): give at least {r // m + 1} rows")
    norms = np.linalg.norm(W, axis=0)
    live = np.flatnonzero(norms > 0)
    rank, perm = 0, np.zeros(0, dtype=int)
    if len(live):  # the rank of the scaled columns, as base_parameters finds it
        R, perm = qr(W[:, live] / norms[live], mode="r", pivoting=True)
        diag = np.abs(np.diag(R))
        rank = int(np.sum(diag > RANK_RTOL * diag[0]))
    if rank < r:
        lost = [int(k) for k in np.flatnonzero(norms == 0)] + [int(live[k]) for k in perm[rank:]]
        listed = "; ".join(base.expressions[k] for k in sorted(lost))
        raise data_error(None, f"these {n} rows cannot identify {r - rank} of the {r} base parameters, which act "
                               f"not at all or only together with others along this motion: {listed}. Record a "
                               "motion that moves every coordinate at varied speeds and accelerations (a robot "
                               "held still identifies no inertia), e.g. identify.excitation")


def _least_squares(W: FloatArray, b: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The least-squares solution of W beta = b and the diagonal of (W^T W)^-1, by one SVD
    of W (full column rank, checked before)."""
    U, s, Vt = np.linalg.svd(W, full_matrices=False)
    beta = Vt.T @ ((U.T @ b) / s)
    return beta, np.sum((Vt.T / s) ** 2, axis=1)


def _consistent(base: BaseParameters, beta: FloatArray, prior: FloatArray, nb: int) -> FloatArray:
    """The full parameters nearest ``prior`` (scaled per parameter) with base parameters
    ``beta``, a physical body each (m > 0, m I_O > (m cx)^2 + (m cy)^2: the first 4 nb) and
    loss parameters >= 0."""
    from scipy.optimize import minimize

    scale = np.maximum(np.abs(prior), 1e-6 * np.abs(prior).max())

    def body_margins(z: FloatArray) -> FloatArray:
        p = z * scale
        b = p[: 4 * nb].reshape(nb, 4)
        return np.concatenate([b[:, 0], b[:, 0] * b[:, 3] - b[:, 1] ** 2 - b[:, 2] ** 2, p[4 * nb:]])

    cons = [{"type": "eq", "fun": lambda z: base.of(z * scale) - beta},
            {"type": "ineq", "fun": body_margins}]
    out = minimize(lambda z: float(np.sum((z - 1.0) ** 2)), np.ones_like(prior), constraints=cons, method="SLSQP",
                   options={"maxiter": 500, "ftol": 1e-14})
    return np.asarray(out.x * scale, dtype=np.float64)


def differentiate(t: ArrayLike, q: ArrayLike, cutoff: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """q filtered by a zero-phase 4th-order Butterworth low-pass at ``cutoff`` (Hz), and its
    first two derivatives by a cubic spline through the filtered samples; t evenly spaced (s),
    at least :data:`MIN_FILTER_ROWS` of them, q (N, m) or (N,).
    Filter the efforts with :func:`lowpass` at the same cutoff (the same delay-free filter on
    both sides keeps the equations), and keep the rows :func:`inside` the record."""
    from scipy.interpolate import CubicSpline

    t = times("t", t, least=MIN_FILTER_ROWS, why="the zero-phase filter's padding at both ends needs them")
    qf = lowpass(t, samples("q", q, len(t), what="rad or m"), cutoff)
    finite_rates(qf, t)
    try:
        spline = CubicSpline(t, qf, axis=0)
    except ValueError:  # scipy's refusal of its own overflow
        raise rates_overflow(qf, t) from None
    qd, qdd = spline(t, 1), spline(t, 2)
    finite_rates(qf, t, qd, qdd)
    return qf if np.ndim(q) == 2 else qf[:, 0], qd, qdd


#: The filter's edge transients spoil about this many periods of the cutoff at each end of
#: a record (4th-order Butterworth run forwards and backwards: measured on an encoder
#: signal, tests/test_identify.py).
EDGE_PERIODS = 2.0


def inside(t: ArrayLike, cutoff: float) -> NDArray[np.bool_]:
    """The rows of a record filtered at ``cutoff`` (Hz) clear of its ends' transients
    (:data:`EDGE_PERIODS` periods of the cutoff at each end)."""
    t = times("t", t, least=1)
    edge = EDGE_PERIODS / positive("cutoff", cutoff, "Hz")
    return np.asarray((t >= t[0] + edge) & (t <= t[-1] - edge))


def lowpass(t: ArrayLike, v: ArrayLike, cutoff: float) -> FloatArray:
    """Zero-phase 4th-order Butterworth low-pass of the columns of v ((N,) or (N, k)) at
    ``cutoff`` (Hz), sampled at times t (N,), at least :data:`MIN_FILTER_ROWS` of them."""
    from scipy.signal import butter, sosfiltfilt

    t = times("t", t, least=MIN_FILTER_ROWS, why="the zero-phase filter's padding at both ends needs them")
    v = array("v", v, ndim=(1, 2))
    if len(v) != len(t):
        raise error("v", f"v has {len(v)} rows where t has {len(t)}: give one row per time")
    cutoff = positive("cutoff", cutoff, "Hz")
    fs = 1.0 / float(np.mean(np.diff(t)))
    if not cutoff < fs / 2:
        raise error("cutoff", f"cutoff = {cutoff:g} Hz must be below half the sampling rate ({fs / 2:g} Hz): "
                              "a lower cutoff, or a record sampled faster")
    if cutoff < MIN_CUTOFF_RATIO * fs / 2:
        raise error("cutoff", f"cutoff = {cutoff:g} Hz is too far below half the sampling rate ({fs / 2:g} Hz; at "
                              f"least {MIN_CUTOFF_RATIO:g} of it) for the filter: a higher cutoff, or a record "
                              "sampled slower")
    # Second-order sections: the transfer-function form loses digits at low cutoffs.
    sos = butter(FILTER_ORDER, cutoff / (fs / 2), output="sos")
    out = np.asarray(sosfiltfilt(sos, v, axis=0), dtype=np.float64)
    if not np.isfinite(out).all():
        raise error("v", f"v's values (largest {np.abs(v).max():.3g}) overflow in the filter: give them in SI units "
                         "of a physical size")
    return out


@dataclass(frozen=True, repr=False)
class Excitation:
    """A periodic motion of the coordinates for identification (:func:`excitation`):
    q_k(t) = q0_k + sum_l a_kl (sin(l w t)) + b_kl (cos(l w t) - 1), w = 2 pi / period.

    ``motion`` is the dict ``Mechanism.simulate(motion=...)`` takes; ``condition`` the
    condition number of the scaled base columns of Y along it, ``start_condition`` that of
    the simple sine it started from."""

    q0: FloatArray
    period: float
    a: FloatArray
    b: FloatArray
    condition: float
    start_condition: float

    def __repr__(self) -> str:
        return (f"Excitation(period {self.period:g} s, {self.a.shape[1]} harmonics on {len(self.q0)} coordinates, "
                f"condition {self.condition:.3g} (the simple sine's {self.start_condition:.3g}))")

    def sample(self, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """q, qd, qdd (N, m) at times t (N,) (s)."""
        # Reduced to one period (exact in floating point): the motion repeats, and a phase
        # l w t of a time far out would overflow.
        t = np.mod(np.atleast_1d(array("t", t, ndim=(0, 1), what="times in s")), self.period)
        w = 2 * np.pi / self.period
        ell = np.arange(1, self.a.shape[1] + 1)
        s, c = np.sin(np.outer(t, ell * w)), np.cos(np.outer(t, ell * w))
        q = self.q0 + s @ self.a.T + (c - 1.0) @ self.b.T
        qd = (c * ell * w) @ self.a.T - (s * ell * w) @ self.b.T
        qdd = -(s * (ell * w) ** 2) @ self.a.T - (c * (ell * w) ** 2) @ self.b.T
        return q, qd, qdd

    def motion(self, names: list[str]) -> dict[str, Any]:
        """For ``Mechanism.simulate(motion=...)``: one function of t per coordinate."""
        return {n: (lambda t, k=k: tuple(float(v[0, k]) for v in self.sample(t))) for k, n in enumerate(names)}


def excitation(mech: Mechanism, period: float = 1.0, harmonics: int = 3, amplitude: float = 0.3,
               samples: int = 100, base: BaseParameters | None = None, max_evaluations: int = 2000,
               tau_max: ArrayLike | None = None, qd_max: ArrayLike | None = None,
               sigma_margin: float | None = None) -> Excitation:
    """A periodic motion that makes the base parameters well observable: the Fourier
    coefficients (``harmonics`` per coordinate) minimising the condition number of the scaled
    base columns of Y over ``samples`` points of a period, from a simple sine (amplitude / 2
    at the first harmonic on every coordinate).

    Constraints along the motion (checked at the ``samples`` points; the reach and speeds on a
    grid 10 times finer per harmonic):

    - every coordinate stays within ``amplitude`` (rad, or 0.1 of it times the drawing's size
      for a displacement) of the model's start;
    - ``qd_max``: (m,) or scalar peak speed of each drive (rad/s or m/s);
    - ``tau_max``: (m,) or scalar peak effort of each drive (N m or N; the motor torque where
      an actuator is), from the model's inverse dynamics (the regressor with the model's
      parameters: tau = Y pi + tau_o);
    - ``sigma_margin``: the type II measure (``kinematics``' ``sigma_min``) stays above it;
    - it can be assembled all along, away from the branch guard of a type II singularity.

    A motion past a limit costs ``INFEASIBLE`` (1 + its worst relative excess), so that the
    search is led back inside. Solved by scipy's Powell method (no derivatives: the objective
    is not smooth where the extreme singular values cross). ``Excitation.start_condition``
    is that of the starting sine, whether or not it kept the limits.
    """
    from scipy.optimize import minimize

    base = _base_of(mech, base)
    m = mech.dof
    period = positive("period", period, "s")
    harmonics = count("harmonics", harmonics, 1, MAX_HARMONICS)
    amplitude = positive("amplitude", amplitude, "rad, or 0.1 of it times the drawing's size for a displacement")
    # m rows a sample: the condition number of the base columns needs at least r rows.
    samples = count("samples", samples, math.ceil(base.rank / m), MAX_SAMPLES)
    max_evaluations = count("max_evaluations", max_evaluations, 1, 10**7)
    reach = np.array([amplitude if k == "angle" else 0.1 * amplitude * mech.scale for k in mech.coordinate_kinds])
    t = np.linspace(0.0, period, samples, endpoint=False)
    # The reach is checked on a grid fine enough that a trigonometric polynomial of this
    # degree cannot exceed it between points by more than (pi h / period)^2 / 2 ~ 1e-5 of it.
    fine = np.linspace(0.0, period, 1000 * harmonics)
    q0 = np.array(mech.q0, float)
    limits = _Limits(mech, tau_max, qd_max, sigma_margin)

    def make(z: FloatArray, start: float = np.inf) -> Excitation:
        a, b = z[: m * harmonics].reshape(m, harmonics), z[m * harmonics:].reshape(m, harmonics)
        return Excitation(q0, period, a * reach[:, None], b * reach[:, None], np.inf, start)

    def cost(z: FloatArray) -> float:
        exc = make(z)
        q_fine, qd_fine, _ = exc.sample(fine)
        excess = max(float(np.max(np.abs(q_fine - q0) / reach)) - 1.0, limits.speed_excess(qd_fine))
        if not excess <= 0.0:
            return _penalty(excess)
        q, qd, qdd = exc.sample(t)
        try:
            Y, tau_o = mech.regressor(q, qd, qdd)
            excess = max(limits.effort_excess(Y, tau_o), limits.sigma_excess(q))
        except PlanardynError:  # not assembled, or too near a singularity
            return INFEASIBLE * 2.0
        if not excess <= 0.0:
            return _penalty(excess)
        W = Y[..., base.independent].reshape(-1, base.rank)
        W = W / np.maximum(np.linalg.norm(W, axis=0), 1e-300)
        return min(float(np.linalg.cond(W)), INFEASIBLE)  # a singular W excites too little: no better

    z0 = np.zeros(2 * m * harmonics)
    z0[::harmonics][:m] = 0.5
    start = cost(z0)
    out = minimize(cost, z0, method="Powell", options={"maxfev": max_evaluations, "xtol": 1e-3, "ftol": 1e-4})
    best, condition = (out.x, float(out.fun)) if out.fun < start else (z0, start)
    if not condition < INFEASIBLE:
        raise PlanardynError(f"no motion found within the limits in {out.nfev} evaluations (the best breaks them, "
                             "cannot be assembled, or excites too few base parameters): loosen tau_max, qd_max or "
                             "sigma_margin, change the amplitude, or allow more harmonics or max_evaluations")
    exc = make(best, start)
    return Excitation(exc.q0, period, exc.a, exc.b, condition, start)


def _penalty(excess: float) -> float:
    """The cost of a motion past its limits by ``excess`` (its worst relative excess; NaN
    counts as far past): ``INFEASIBLE`` (1 + excess), the excess capped at EXCESS_CAP so that
    the cost stays finite for Powell's line searches."""
    return INFEASIBLE * (1.0 + (min(excess, EXCESS_CAP) if excess == excess else EXCESS_CAP))


class _Limits:
    """The drives' limits of :func:`excitation`, each as a worst relative excess (> 0: past it)."""

    def __init__(self, mech: Mechanism, tau_max: ArrayLike | None, qd_max: ArrayLike | None,
                 sigma_margin: float | None) -> None:
        self.mech = mech
        self.pi = np.array(list(mech.regressor_parameters.values()))
        self.tau_max = limits("tau_max", tau_max, mech.dof, "N m or N, a peak effort per drive")
        self.qd_max = limits("qd_max", qd_max, mech.dof, "rad/s or m/s, a peak speed per drive")
        if sigma_margin is not None:
            sigma_margin = positive("sigma_margin", sigma_margin, "a type II measure")
        self.sigma_margin = sigma_margin

    def speed_excess(self, qd: FloatArray) -> float:
        return -1.0 if self.qd_max is None else float(np.max(np.abs(qd) / self.qd_max)) - 1.0

    def effort_excess(self, Y: FloatArray, tau_o: FloatArray) -> float:
        if self.tau_max is None:
            return -1.0
        return float(np.max(np.abs(Y @ self.pi + tau_o) / self.tau_max)) - 1.0

    def sigma_excess(self, q: FloatArray) -> float:
        if self.sigma_margin is None:
            return -1.0
        x, least = None, np.inf
        for row in q:  # continued point to point: the branch of the start
            k = self.mech.kinematics(row, x_start=x)
            x, least = k["x"], min(least, k["sigma_min"])
        return self.sigma_margin / max(least, 1e-300) - 1.0
