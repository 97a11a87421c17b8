"""The dense output on steps integrated in a partition chart (near a singularity of the user's
coordinates): `res.sol` against the outputs, which are the chart's interpolant assembled at
each output time. There q(t) is not a polynomial, and through the step's p + 1 assembled points
alone sol's qd was up to 85 times the run's tolerance off the outputs (five-bar free fall,
DOPRI5 at rtol 1e-5; 30 on the geared five-bar at 1e-6); stored in
`simulate::dense::PARTITION_PIECES` pieces it is below 0.17 of it at rtol 1e-5 ... 1e-9 (the
bound below, 0.5, leaves room; from rtol 1e-10 the difference is the assembly's round-off near
the singularity instead, 1e-10 ... 3e-10 rad/s, 0.51 of the tolerance at 1e-10, so those
tolerances are not checked here)."""

from __future__ import annotations

import numpy as np
import planardyn as pd
import planardyn.library as lib
import pytest

#: The largest |sol - output| allowed, as a fraction of the run's tolerance atol + rtol |value|.
WITHIN = 0.5


@pytest.mark.parametrize("example", ["five-bar-free-fall", "geared-five-bar"])
@pytest.mark.parametrize("method", ["dopri5", "dop853", "radau5"])
@pytest.mark.parametrize("rtol", [1e-5, 1e-7, 1e-9])
def test_sol_follows_the_outputs_on_steps_in_a_partition_chart(example, method, rtol):
    mech = pd.load_example(example)
    atol = 1e-3 * rtol
    res = mech.simulate(t_end=1.0, method=method, rtol=rtol, atol=atol, output_dt=1e-3, dense_output=True)
    assert res.success, res.message
    assert res.stats["partition_steps"] > 0
    q, qd = res.sol(res.t)
    assert (np.abs(q - res.q) / (atol + rtol * np.abs(res.q))).max() < WITHIN
    assert (np.abs(qd - res.qd) / (atol + rtol * np.abs(res.qd))).max() < WITHIN


def _swing_through_the_change_point(**kwargs):
    # The double parallelogram released at 2 rad swings through theta1 = pi, where its cranks
    # lie along the ground line (a change point), at 0.336 s; the crossing's gap is bridged.
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # its redundant constraint
        mech = lib.double_parallelogram(theta=2.0)
    return mech.simulate(
        t_end=1.0, method="dop853", rtol=1e-10, atol=1e-12, output_dt=1e-3, dense_output=True, **kwargs
    )


def test_sol_follows_the_outputs_through_a_change_point_crossing():
    # Before the crossing's gap was stored, the step after the landing was stretched over it:
    # sol was 0.33 rad off the outputs there. Inside the gap both are the bridge's.
    res = _swing_through_the_change_point()
    assert res.success, res.message
    assert np.abs(res.q[:, 0] - np.pi).min() < 1e-2
    q, qd = res.sol(res.t)
    assert (np.abs(q - res.q) / (1e-12 + 1e-10 * np.abs(res.q))).max() < WITHIN
    assert (np.abs(qd - res.qd) / (1e-12 + 1e-10 * np.abs(res.qd))).max() < WITHIN


def test_a_terminal_event_inside_a_change_point_crossing_ends_the_run_there():
    # theta1 = pi is the change point itself, inside the gap; the event is found there, the
    # last row is at it (from the bridge), and sol ends there.
    res = _swing_through_the_change_point(events=[pd.Crossing("theta1", np.pi, terminal=True)])
    assert res.status == "event", res.message
    (t_star,) = res.t_events[0]
    assert res.t[-1] == t_star and 0.33 < t_star < 0.34
    assert abs(res.q[-1, 0] - np.pi) < 1e-9 and abs(res.q_events[0][0, 0] - np.pi) < 1e-9
    assert abs(res.sol(t_star)[0][0] - np.pi) < 1e-9
