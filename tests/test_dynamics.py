"""The dynamics calls: no finite garbage and no NaN/inf (below), and inverse dynamics on the
branch the motion took (its section at the end).

Near the slider-driven slider-crank's dead centre (slider at r + l = 0.4 m) the analogues grow
as 1/sigma and the results lost every digit while looking like numbers (inverse dynamics 9.8e25
at sigma 5.7e-8); below ``planardyn::dynamics::SINGULAR_SIGMA`` = 1e-6 the four dynamics calls
raise ``SingularityError`` (kind 'type_ii', ``sigma_min``), or compute with
``allow_singular=True``. Finite inputs whose results overflow raise ``ValueError`` naming the
quantity, never return NaN or inf.
"""

from __future__ import annotations

import numpy as np
import planardyn as pd
import pytest
from planardyn.results_io import inverse_from_file, write_results

SINGULAR_SIGMA = 1e-6
DEAD_CENTRE = 0.4  # m: crank 0.1 m + rod 0.3 m, guide through the crank pivot


@pytest.fixture(scope="module")
def slider():
    return pd.load_example("library/slider-crank-slider-driven")


def near(mech, d):
    q = np.array([DEAD_CENTRE - d])
    return q, mech.kinematics(q)["sigma_min"]


CALLS = {
    "mass_matrix": lambda m, q, **kw: m.mass_matrix(q, **kw),
    "forward_dynamics": lambda m, q, **kw: m.forward_dynamics(q, [0.0], tau=[0.0], **kw),
    "inverse_dynamics": lambda m, q, **kw: m.inverse_dynamics(q, [0.1], [1.0], **kw),
    "reactions": lambda m, q, **kw: m.reactions(q, [0.0], tau=[0.0], **kw),
}


@pytest.mark.parametrize("name", list(CALLS))
def test_at_the_dead_centre_each_call_is_refused_with_the_measure(slider, name):
    q, sigma = near(slider, 1e-14)
    assert sigma < SINGULAR_SIGMA
    with pytest.raises(pd.SingularityError, match="type II") as err:
        CALLS[name](slider, q)
    assert err.value.kind == "type_ii"
    # The core's estimate of the measure stops within its SIGMA_RTOL (2e-3) of the SVD.
    assert err.value.sigma_min == pytest.approx(sigma, rel=2e-3)
    # On request the value is computed (and is finite) instead.
    assert np.all(np.isfinite(CALLS[name](slider, q, allow_singular=True)))


def test_just_above_the_threshold_forward_and_inverse_agree(slider):
    q, sigma = near(slider, 1e-10)
    assert SINGULAR_SIGMA < sigma < 100 * SINGULAR_SIGMA
    tau = slider.inverse_dynamics(q, [0.1], [1.0])
    qdd = slider.forward_dynamics(q, [0.1], tau=tau)
    # Round-off grows as the measure falls (test dynamics_guards.rs measures it): 1e-3 is the
    # accuracy the threshold keeps.
    assert qdd[0] == pytest.approx(1.0, rel=1e-3)


def test_huge_efforts_are_an_overflow_error():
    mech = pd.load_example("five-bar-free-fall")
    with pytest.raises(ValueError, match="accelerations qdd overflow") as err:
        mech.forward_dynamics(mech.q0, [0.0, 0.0], tau=[1e308, 1e308])
    assert err.value.quantity == "accelerations qdd"


@pytest.mark.parametrize("run", [{"qd0": [1e308]}, {"qd0": [1e154]}, {"motion": {"theta1": 1e308}},
                                 {"drives": lambda t, q, qd: [1e308]}])
def test_a_run_that_overflows_says_what_to_make_smaller(run):
    # At 5816799 these stopped with status non_finite and only "NaN or infinity in the
    # solution near t = 0 s", naming no argument (s22-check); forward_dynamics names them.
    res = pd.load_example("four-bar-gravity").simulate(0.1, **run)
    assert res.status == "non_finite" and not res.success
    assert "NaN or infinity in the solution near t = 0 s" in res.message
    assert "try smaller start rates (qd0), efforts or motion speeds" in res.message
    assert np.all(np.isfinite(res.q)) and np.all(np.isfinite(res.qd))


@pytest.mark.parametrize("example", ["four-bar-gravity", "five-bar-free-fall", "slider-crank"])
def test_start_rates_too_large_to_integrate_are_named(example):
    # qd0 1e20 rad/s moves the mechanism 1e6 rad in the smallest step (h_min 1e-14 s): the
    # step failed with a failed position analysis's advice, "try values closer to the drawing"
    # (the four-bar, the five-bar), or "try radau5" (the slider-crank's underflow), naming no
    # argument (s22-check N1).
    mech = pd.load_example(example)
    res = mech.simulate(0.1, qd0=[1e20] * mech.dof)
    assert not res.success and res.status in ("assembly_failed", "step_size_underflow")
    assert res.message.startswith("the start rates qd0 are too large to integrate: the mechanism moves ")
    assert "give smaller start rates (qd0). The step failed with: " in res.message


@pytest.mark.parametrize(
    ("call", "quantity"),
    [
        (lambda m, q, v: m.forward_dynamics(q, v), "accelerations qdd"),
        (lambda m, q, v: m.reactions(q, v), "accelerations qdd"),
        (lambda m, q, v: m.inverse_dynamics(q, v, [0.0, 0.0]), "efforts tau"),
        (lambda m, q, v: m.kinematics(q, v), "convective accelerations c"),
        (lambda m, q, v: m.energy(q, v), "energies"),
    ],
)
def test_huge_rates_are_an_overflow_error(call, quantity):
    mech = pd.load_example("five-bar-free-fall")
    with pytest.raises(ValueError, match="try smaller efforts") as err:
        call(mech, mech.q0, [1e155, 1e155])
    assert err.value.quantity == quantity


def test_a_run_of_no_step_reports_the_start_measure_not_inf():
    # A drive that fails after the start: the first step is never accepted.
    def drives(t, q, qd):
        if t > 0.0:
            raise RuntimeError("no effort after the start")
        return np.zeros(2)

    mech = pd.load_example("five-bar-free-fall")
    res = mech.simulate(t_end=1.0, drives=drives)
    assert res.status == "drive_failed" and res.stats["naccept"] == 0
    sigma0 = mech.kinematics(mech.q0)["sigma_min"]
    # The integrator's estimate of the measure, within its SIGMA_RTOL (2e-3) of the SVD.
    assert res.stats["min_sigma"] == pytest.approx(sigma0, rel=2e-3)


@pytest.mark.parametrize("k", range(600, 1351, 50))
def test_free_fall_steps_stay_within_half_the_time_to_a_type_ii_singularity_in_the_solution(k):
    # DOPRI5 at rtol = atol = 10^(-k/150) (1e-4 ... 1e-9), rows at the steps. While the user's
    # chart's measure falls below 0.25, its equations are singular a time T = sigma^2 / (d sigma^2
    # / dt) ahead (sigma^2 about linear in t, here from the last two rows), and the embedded
    # estimate bounds the error only for steps up to T/2 (simulate/charts.rs, USER_FALL). The
    # exception is a passage the motion makes analytically, its accelerations tending to a finite
    # limit: the growth d|qdd|/d(1/sigma) positive and falling. Once it is not, the rest of the
    # fall keeps the bound. Before (d0abcad) every one of 251 such runs (k = 600 ... 1350 by 3)
    # had steps of up to 0.95 T there; now none over T/2 (to rounding of T from the rows).
    mech = pd.load_example("five-bar-free-fall")
    r = 10 ** (-k / 150)
    res = mech.simulate(t_end=1.0, method="DOPRI5", rtol=r, atol=r)
    t, s, part = res.t, res.sigma, res.partitioned
    size = np.linalg.norm(res.qdd, axis=1)
    singular, last_growth, worst = False, np.nan, 0.0
    for i in range(1, len(t) - 1):
        user = not (part[i - 1] or part[i])
        growth = (size[i] - size[i - 1]) / (1 / s[i] - 1 / s[i - 1]) if user and t[i] > t[i - 1] else np.nan
        analytic = 0 < growth < last_growth
        singular = user and s[i] < s[i - 1] and (singular or (s[i] < 0.25 and not analytic))
        last_growth = growth
        if singular and not part[i + 1]:
            time_to_it = s[i] ** 2 * (t[i] - t[i - 1]) / (s[i - 1] ** 2 - s[i] ** 2)
            worst = max(worst, (t[i + 1] - t[i]) / time_to_it)
    assert worst <= 0.5 + 1e-9, f"a step covers {worst:.3f} of the time to the singularity"


def test_free_fall_drift_follows_the_tolerance_through_the_alternative_charts():
    # DOPRI5 at rtol = atol = 10^(-k/20), k = 20 ... 200 (benchmarks/drift_outliers.py's sweep):
    # no run's drift is over 10 times the geometric mean of its neighbours' (that benchmark's
    # FACTOR, its mark of an isolated failure of the error estimate). Before the alternative
    # charts' falls were bounded (simulate/charts.rs, FallWatch), k = 67 (rtol 4.47e-4) drifted
    # 6.2e-3 J, 13.3x its neighbours': one step in the pairs' chart from own measure 0.103 to
    # 0.080, past the time to that chart's singularity. Now the largest ratio is 3.4 (k = 57).
    mech = pd.load_example("five-bar-free-fall")
    drift = []
    for k in range(20, 201):
        r = 10 ** (-k / 20)
        res = mech.simulate(t_end=1.0, method="DOPRI5", rtol=r, atol=r)
        assert res.success
        drift.append(np.max(np.abs(res.energy.balance)))
    d = np.array(drift)
    ratio = d[1:-1] / np.sqrt(d[:-2] * d[2:])
    worst = int(np.argmax(ratio))
    assert ratio[worst] < 10, f"k = {worst + 21}: drift {d[worst + 1]:.3g} J, {ratio[worst]:.1f}x its neighbours'"


@pytest.mark.parametrize("k", range(20, 201, 15))
def test_free_fall_steps_from_a_peak_stay_within_half_the_time_to_the_curved_fall(k):
    # DOPRI5 at rtol = atol = 10^(-k/20), rows at the steps. Where sigma^2 through the last three
    # points of the user's chart is concave, the measure may fall from a peak faster than the two
    # points' slope says; the next step covers at most half the time to where that parabola
    # reaches 0 (simulate/charts.rs, curved_fall_time and USER_FALL), to rounding of T from the
    # rows. Before it (3b0e891) 10 of these 13 runs had a step over it, up to 2.77 of that time
    # (k = 20); at k = 20 and 26 one step from sigma 0.28 - 0.30 fell to 0.11 - 0.13 in 27 - 28 ms
    # and gained 0.33 - 0.50 J (the drift at k = 20 ... 27 was 0.36 - 0.51 J; now 0.0056 - 0.126 J).
    # The watch takes its first point at the end of the run's first step (not the start), so its
    # first parabola is at the third step's end (row 3).
    mech = pd.load_example("five-bar-free-fall")
    r = 10 ** (-k / 20)
    res = mech.simulate(t_end=1.0, method="DOPRI5", rtol=r, atol=r)
    t, s2, part = res.t, res.sigma**2, res.partitioned
    worst = 0.0
    for i in range(3, len(t) - 1):
        if part[i - 2 : i + 2].any():
            continue
        d1 = (s2[i - 1] - s2[i - 2]) / (t[i - 1] - t[i - 2])
        d2 = (s2[i] - s2[i - 1]) / (t[i] - t[i - 1])
        dd = (d2 - d1) / (t[i] - t[i - 2])
        if dd < 0:
            g = d2 + dd * (t[i] - t[i - 1])
            time_to_zero = (g + np.sqrt(g * g - 4 * dd * s2[i])) / (-2 * dd)
            worst = max(worst, (t[i + 1] - t[i]) / time_to_zero)
    assert worst <= 0.5 + 1e-9, f"a step covers {worst:.3f} of the time to the curved fall's zero"


# ---------------------------------------------------------------- inverse dynamics on the motion's branch
# Inverse dynamics follows the branch the motion took.
#
# A motion that passes through a type II singularity may leave it on the other assembly
# branch: the free-falling five-bar does, and a slider-crank pushed through its dead centre.
# Their efforts are known exactly: the five-bar is passive (the truth is 0), the slider-crank
# ran under its model's drives (the truth is the run's own ``tau``). With the body coordinates
# of every row (a result's ``x``, which results files carry) the efforts match; from q alone
# the rows after the singularity are refused, naming the row, instead of being computed on
# the drawn branch (they were off by up to 2.28e3 N m).

TIGHT = dict(method="dop853", rtol=1e-10, atol=1e-12)


def first_crossing(sigma):
    """The row where a run first passes its type II singularity: the first minimum of the
    measure below 0.05. (Its chart is no mark of it: a run leaves the user's chart for an
    alternative one from 0.07, before the measure is that low.)"""
    return int(np.flatnonzero((sigma[:-1] < 0.05) & (sigma[1:] > sigma[:-1]))[0])


@pytest.fixture(scope="module")
def free_fall():
    mech = pd.load_example("five-bar-free-fall")
    res = mech.simulate(t_end=1.0, **TIGHT)
    # The run itself goes through a type II singularity (it switches to body coordinates).
    assert res.success and res.partitioned.any()
    return mech, res


def test_free_fall_efforts_are_zero_from_the_result(free_fall):
    mech, res = free_fall
    # With the run's body rates: at its most singular row (sigma 8.6e-4) one rounding unit of
    # qd moves the rates solved from it, and the efforts by ~2e-8 N m (2.5e-8 measured from
    # x alone); xd holds the integrator's state.
    tau = mech.inverse_dynamics(res.q, res.qd, res.qdd, x=res.x, xd=res.xd)
    # Passive: 0 exactly; 1e-8 N m is the bound, ~1e4 times the round-off of A qdd - b.
    assert np.abs(tau).max() < 1e-8


def test_free_fall_efforts_are_zero_from_its_results_file(free_fall, tmp_path):
    mech, res = free_fall
    path = tmp_path / "free-fall.npz"
    write_results(res, path)
    # The file's xd are passed with its x (see the test above for why).
    inv = inverse_from_file(mech, path)
    assert np.abs(inv.tau).max() < 1e-8
    assert np.array_equal(inv.xd, res.xd)
    assert inv.metadata["branch"] == "each row's body coordinates"
    assert np.allclose(inv.x, res.x, atol=1e-9)


def test_body_rates_that_are_not_qd_s_are_refused_naming_the_row(free_fall):
    mech, res = free_fall
    xd = res.xd.copy()
    # Another state's rates: one body's angular rate off by 1e-6 rad/s, far above the
    # round-off (relative 1e-10 accepted) and far below the rates themselves (~1-10 rad/s).
    xd[7, 2] += 1e-6
    with pytest.raises(ValueError, match="row 7"):
        mech.inverse_dynamics(res.q, res.qd, res.qdd, x=res.x, xd=xd)
    # 1e-12 rad/s off is within RATES_TOL of the largest body rate: accepted, the efforts
    # still 0 to the bound of the test above.
    xd[7, 2] -= 1e-6 - 1e-12
    assert np.abs(mech.inverse_dynamics(res.q, res.qd, res.qdd, x=res.x, xd=xd)).max() < 1e-8
    with pytest.raises(ValueError, match="xd needs x"):
        mech.inverse_dynamics(res.q, res.qd, res.qdd, xd=res.xd)


def test_free_fall_from_q_alone_is_refused_at_the_singularity(free_fall):
    mech, res = free_fall
    with pytest.raises(pd.SingularityError, match="cannot be decided") as err:
        mech.inverse_dynamics(res.q, res.qd, res.qdd)
    row = err.value.row
    # Refused at a row where the drawn branch is within 0.05 of the singularity, and before the
    # motion left it (row 21 of the crossing at row 23).
    assert err.value.sigma_min < 0.05
    assert 0 < row < first_crossing(res.sigma)


# The weight of the slider-crank's crank, rod and slider (0.1 + 0.3 + 0.5 kg), N: its efforts' scale.
SLIDER_CRANK_WEIGHT = 0.9 * 9.81


@pytest.mark.parametrize("v0", [-3.0, 3.0])
@pytest.mark.parametrize("rtol", [1e-10, 1.122e-10])
def test_slider_crank_through_its_dead_centre(v0, rtol):
    mech = pd.load_example("library/slider-crank-slider-driven")
    res = mech.simulate(t_end=1.0, qd0=[v0], **{**TIGHT, "rtol": rtol})
    assert res.success and res.partitioned.any()
    # Each row's efforts against the run's, within what rounding explains at its distance from
    # the dead centre (sigma): with the run's body rates, qdd's rounding moves them like
    # eps W / sigma^2; from x alone, q's like eps W / sigma^4. The factors 100 and 2 are ~10x
    # the largest measured over rtol 1e-10 x 10^(j/100), |j| <= 30, both directions (9.7 and
    # 0.15; rows down to sigma 5.8e-6, where the errors reach 4e-6 N and 9e-3 N). A real error
    # of the run's qdd or tau does not shrink like sigma^2 away from the dead centre: at sigma
    # 0.1 the bound with xd is 2e-11 N.
    eps, sigma = np.finfo(float).eps, res.sigma[:, None]
    with_rates = mech.inverse_dynamics(res.q, res.qd, res.qdd, x=res.x, xd=res.xd)
    assert np.all(np.abs(with_rates - res.tau) <= 100 * eps * SLIDER_CRANK_WEIGHT / sigma**2)
    from_x = mech.inverse_dynamics(res.q, res.qd, res.qdd, x=res.x)
    assert np.all(np.abs(from_x - res.tau) <= 2 * eps * SLIDER_CRANK_WEIGHT / sigma**4)
    with pytest.raises(pd.SingularityError) as err:
        mech.inverse_dynamics(res.q, res.qd, res.qdd)
    assert err.value.row < first_crossing(res.sigma)  # rtol 1e-10: rows 11 and 14, crossings at 15 and 18


def test_a_single_row_near_a_singularity_is_not_refused(free_fall):
    # One row has no "after": nothing to decide. At the run's most singular row (sigma
    # 8.6e-4) the passive efforts are still 0 to round-off amplified by 1/sigma, given the
    # row's body rates (from qd's rounding alone they are 2.5e-8 N m off).
    mech, res = free_fall
    i = int(np.argmin(res.sigma))
    tau = mech.inverse_dynamics(res.q[i], res.qd[i], res.qdd[i], x=res.x[i], xd=res.xd[i])
    assert np.abs(tau).max() < 1e-8
