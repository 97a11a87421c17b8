"""The dense output on steps integrated in a partition chart (near a singularity of the user's
coordinates): `res.sol` against the outputs, which are the chart's interpolant assembled at
each output time. There q(t) is not a polynomial, and through the step's p + 1 assembled points
alone sol's qd was up to 85 times the run's tolerance off the outputs (five-bar free fall,
DOPRI5 at rtol 1e-5; 30 on the geared five-bar at 1e-6); stored in
`simulate::dense::PARTITION_PIECES` pieces it is below 0.3 of it at rtol 1e-5 ... 1e-10 (the
bound below, 0.5, leaves room; at rtol 1e-12 the difference is the assembly's round-off near
the singularity instead, 2e-10 rad/s, so that tolerance is not checked here)."""

from __future__ import annotations

import numpy as np
import planardyn as pd
import pytest

#: The largest |sol - output| allowed, as a fraction of the run's tolerance atol + rtol |value|.
WITHIN = 0.5


@pytest.mark.parametrize("example", ["five-bar-free-fall", "geared-five-bar"])
@pytest.mark.parametrize("method", ["dopri5", "dop853", "radau5"])
@pytest.mark.parametrize("rtol", [1e-5, 1e-8, 1e-10])
def test_sol_follows_the_outputs_on_steps_in_a_partition_chart(example, method, rtol):
    mech = pd.load_example(example)
    atol = 1e-3 * rtol
    res = mech.simulate(t_end=1.0, method=method, rtol=rtol, atol=atol, output_dt=1e-3, dense_output=True)
    assert res.success, res.message
    assert res.stats["partition_steps"] > 0
    q, qd = res.sol(res.t)
    assert (np.abs(q - res.q) / (atol + rtol * np.abs(res.q))).max() < WITHIN
    assert (np.abs(qd - res.qd) / (atol + rtol * np.abs(res.qd))).max() < WITHIN
