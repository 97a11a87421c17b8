"""Events and dense output of Mechanism.simulate against closed forms: the pendulum released
from rest at theta0 reaches the vertical at a quarter of its exact period K(k) / omega
(k = sin(theta0 / 2), Landau & Lifshitz sec. 11), turns back at T/2 and T; a coordinate
driven at constant speed crosses a value at a time known exactly."""

from __future__ import annotations

import math

import numpy as np
import planardyn as pd
import pytest
from conftest import PENDULUM_I, PENDULUM_L, PENDULUM_M, G, cli_run, pendulum_dict
from scipy.special import ellipk

THETA0 = 1.0  # rad from the downward vertical, released at rest
OMEGA = math.sqrt(PENDULUM_M * G * PENDULUM_L / (PENDULUM_I + PENDULUM_M * PENDULUM_L**2))
QUARTER = ellipk(math.sin(THETA0 / 2) ** 2) / OMEGA  # s (scipy's ellipk takes m = k^2)


def released(pendulum, **kw):
    return pendulum.simulate(q0=[THETA0], rtol=1e-12, atol=1e-14, **kw)


def test_terminal_crossing_stops_at_the_quarter_period(pendulum):
    res = released(pendulum, t_end=2.0, events=[pd.Crossing("theta", 0.0, terminal=True, direction=-1)])
    assert res.status == "event" and res.success, res.message
    (t_star,) = res.t_events[0]
    # rtol 1e-12: the solution, and so the crossing, is good to about 1e-11 s.
    assert t_star == pytest.approx(QUARTER, abs=1e-9)
    assert res.t[-1] == t_star and np.all(res.t[:-1] < t_star)
    assert res.q[-1, 0] == pytest.approx(0.0, abs=1e-12)
    # Energy at the bottom: qd^2 = 2 omega^2 (1 - cos theta0).
    assert res.qd_events[0][0, 0] == pytest.approx(-OMEGA * math.sqrt(2 * (1 - math.cos(THETA0))), abs=1e-9)
    assert res.q_events[0].shape == (1, 1)


def test_a_function_event_finds_both_turning_points(pendulum):
    period = 4 * QUARTER

    def turning(t, q, qd):
        return qd[0]

    rising = lambda t, q, qd: qd[0]  # noqa: E731
    rising.direction = 1  # type: ignore[attr-defined]
    res = released(pendulum, t_end=1.2 * period, t_eval=[0.0, 1.2 * period], events=[turning, rising])
    assert res.status == "success", res.message
    assert res.sol is None  # kept only with dense_output=True
    # qd = 0 at t = 0 is the start, not a crossing; then T/2 (rising) and T (falling).
    np.testing.assert_allclose(res.t_events[0], [period / 2, period], atol=1e-8)
    np.testing.assert_allclose(res.q_events[0][:, 0], [-THETA0, THETA0], atol=1e-8)
    np.testing.assert_allclose(res.t_events[1], [period / 2], atol=1e-8)


def test_sol_reproduces_the_outputs_and_is_vectorised(pendulum):
    res = released(pendulum, t_end=4 * QUARTER, output_dt=0.05, dense_output=True)
    q, qd = res.sol(res.t)
    assert q.shape == qd.shape == (len(res.t), 1)
    # The same interpolant as the output rows, evaluated another way: round-off.
    np.testing.assert_allclose(q, res.q, rtol=0, atol=1e-13)
    np.testing.assert_allclose(qd, res.qd, rtol=0, atol=1e-12)
    # Between the outputs, energy conservation: qd^2 = 2 omega^2 (cos q - cos theta0), to
    # the integrator's accuracy.
    t = np.linspace(0.0, 4 * QUARTER, 777)
    q, qd = res.sol(t)
    np.testing.assert_allclose(qd[:, 0] ** 2, 2 * OMEGA**2 * (np.cos(q[:, 0]) - math.cos(THETA0)), atol=1e-9)
    q1, qd1 = res.sol(QUARTER)
    assert q1.shape == (1,) and q1[0] == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(ValueError, match="outside the run"):
        res.sol(4 * QUARTER + 0.01)
    assert released(pendulum, t_end=0.1).sol is None


def test_events_on_a_coordinate_driven_by_motion(pendulum):
    # theta driven at 0.5 rad/s from 0 passes 0.3 rad at 0.6 s exactly.
    res = pendulum.simulate(t_end=2.0, output_dt=0.25, motion={"theta": lambda t: (0.5 * t, 0.5, 0.0)},
                            events=[pd.Crossing("theta", 0.3, terminal=True)], dense_output=True)
    assert res.status == "event", res.message
    assert res.t_events[0][0] == pytest.approx(0.6, abs=1e-12)
    np.testing.assert_array_equal(res.t[:-1], [0.0, 0.25, 0.5])
    assert res.q[-1, 0] == pytest.approx(0.3, abs=1e-12)
    assert res.sol.t_max == res.t[-1]


def test_an_event_that_raises_ends_the_run_with_its_reason(pendulum):
    def broken(t, q, qd):
        if t > 0.2:
            raise RuntimeError("sensor lost")
        return 1.0

    res = released(pendulum, t_end=1.0, events=[broken])
    assert res.status == "event_failed" and not res.success
    assert "sensor lost" in res.message
    with pytest.raises(ValueError, match="unknown coordinate 'phi'"):
        pendulum.simulate(events=[pd.Crossing("phi", 0.0)])
    with pytest.raises(TypeError, match="Crossing"):
        pendulum.simulate(events=[3.0])


def test_cli_stop_when(tmp_path):
    import json

    model = tmp_path / "pendulum.json"
    spec = pendulum_dict()
    spec["coordinates"][0]["q0"] = THETA0
    spec["simulate"] = {"t_end": 2.0, "rtol": 1e-12, "atol": 1e-14}
    model.write_text(json.dumps(spec))
    out = tmp_path / "run.csv"
    code, err = cli_run("simulate", model, "--stop-when", "theta<0", "-o", out, "--no-progress")
    assert code == 0, err
    res = pd.read_results(out)
    assert res.status == "event"
    assert res.t[-1] == pytest.approx(QUARTER, abs=1e-9)
    # The file keeps the events, exactly.
    assert res.t_events[0].tolist() == [res.t[-1]] and res.q_events[0].shape == (1, 1)
    code, err = cli_run("simulate", model, "--stop-when", "theta~0")
    assert code == 2 and "NAME=VALUE" in err


def test_one_event_alone_is_taken_as_solve_ivp_takes_it(pendulum):
    # A lone Crossing or function used to fail inside the package ("'Crossing' object is not
    # iterable"); solve_ivp takes one event without a list (s15-sweep).
    def bottom(t, q, qd):
        return q[0]

    bottom.terminal = True
    for event in (pd.Crossing("theta", 0.0, terminal=True), bottom):
        res = released(pendulum, t_end=2.0, events=event)
        assert res.status == "event" and res.t_events[0][0] == pytest.approx(QUARTER, abs=1e-9), res.message
        assert len(res.metadata["settings"]["events"]) == 1
    with pytest.raises(TypeError, match="events must be an event or a list of them"):
        released(pendulum, t_end=2.0, events=3.0)
