"""Prescribed motion through the API, the model file and the CLI.

The pendulum of conftest driven by motion needs, in closed form, the torque
tau = I_O qdd + m g l sin(q) with I_O = I + m l^2 (q from the downward vertical); a motion
q = q0 + w t therefore needs m g l sin(q), and its work m g l (cos q0 - cos q) equals the rise
of V. The mixed run (a crank at constant speed, a spring-loaded rider free) checks the energy
balance T + V - W, W including the crank torque's work.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import planardyn as pd
import pytest
from conftest import PENDULUM_I, PENDULUM_L, PENDULUM_M, G, cli_run, pendulum_dict
from planardyn.results_io import read_results

I_O = PENDULUM_I + PENDULUM_M * PENDULUM_L**2
MGL = PENDULUM_M * G * PENDULUM_L
W = 2 * math.pi  # rad/s


def closed_form_torque(q, qdd):
    return I_O * qdd + MGL * np.sin(q)


@pytest.fixture
def pendulum():
    return pd.from_dict(pendulum_dict())


def test_constant_speed_torque_and_work_match_the_closed_form(pendulum):
    res = pendulum.simulate(1.0, output_dt=0.01, motion={"theta": W})
    assert res.success, res.message
    np.testing.assert_allclose(res.q[:, 0], W * res.t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.qd[:, 0], W, rtol=0, atol=1e-12)
    # Same equations as the closed form, to round-off of A and b (1e-12 of m g l ~ 1.2 N m).
    np.testing.assert_allclose(res.tau[:, 0], MGL * np.sin(W * res.t), rtol=0, atol=1e-11)
    # W = m g l (1 - cos w t): integrated by DOP853 at rtol 1e-9 (the model default).
    np.testing.assert_allclose(res.energy.work, MGL * (1 - np.cos(W * res.t)), rtol=0, atol=1e-9)
    assert res.stats["energy_drift"] < 1e-9


def test_function_and_table_motions_match_the_closed_form(pendulum):
    amp, om = 0.8, 3.0

    def swing(t):
        return amp * math.sin(om * t), amp * om * math.cos(om * t), -amp * om**2 * math.sin(om * t)

    res = pendulum.simulate(2.0, output_dt=0.05, motion={"theta": swing})
    assert res.success, res.message
    q, qdd = amp * np.sin(om * res.t), -amp * om**2 * np.sin(om * res.t)
    np.testing.assert_allclose(res.q[:, 0], q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.tau[:, 0], closed_form_torque(q, qdd), rtol=0, atol=1e-10)
    # A table of a cubic: the not-a-knot spline reproduces it, ends included (no invented stop).
    t = np.linspace(0.0, 1.0, 7)
    cubic = np.poly1d([-1.5, 2.0, 3.0, 0.2])
    res = pendulum.simulate(1.0, t_eval=[0.0, 0.37, 1.0], motion={"theta": {"t": t, "q": cubic(t)}})
    assert res.success, res.message
    tt = res.t
    np.testing.assert_allclose(res.qd[:, 0], cubic.deriv()(tt), rtol=0, atol=1e-11)
    np.testing.assert_allclose(res.tau[:, 0], closed_form_torque(cubic(tt), cubic.deriv(2)(tt)), rtol=0, atol=1e-9)


SHAKER = {
    "name": "shaker",
    "gravity": [0, -9.81],
    "points": {"O": [0, 0], "A": [0.08660254037844387, 0.05], "B": [0.43531445586169776, 0.02],
               "C": [0.53531445586169776, 0.02]},
    "ground": ["O"],
    "bodies": {
        "crank": {"points": ["O", "A"], "uniform_bar": ["O", "A"], "mass": 0.3},
        "rod": {"points": ["A", "B"], "uniform_bar": ["A", "B"], "mass": 0.6},
        "slider": {"points": ["B"], "mass": 0.5, "inertia": 0.001, "com": "B"},
        "rider": {"points": ["C"], "mass": 0.2, "inertia": 0.0005, "com": "C"},
    },
    "pairs": [
        {"type": "revolute", "name": "O", "at": "O", "bodies": ["ground", "crank"]},
        {"type": "revolute", "at": "A", "bodies": ["crank", "rod"]},
        {"type": "revolute", "at": "B", "bodies": ["rod", "slider"]},
        {"type": "prismatic", "name": "guide", "at": "B", "bodies": ["ground", "slider"], "axis": [1, 0]},
        {"type": "prismatic", "name": "ride", "at": "C", "bodies": ["slider", "rider"], "axis": [1, 0]},
    ],
    "coordinates": [{"name": "phi", "pair": "O", "value": 0.5235987755982988},
                    {"name": "s", "pair": "ride", "value": 0.0, "qd0": 0.3}],
    "drives": [{"coordinate": "phi", "motion": {"speed": W}}],
    "loads": [{"type": "spring", "between": [["slider", "B"], ["rider", "C"]], "stiffness": 80.0, "rest_length": 0.1}],
}


def test_mixed_run_from_the_model_file_closes_its_energy_balance():
    mech = pd.from_dict(SHAKER)
    res = mech.simulate(2.0, output_dt=0.01, rtol=1e-10, atol=1e-13)
    assert res.success, res.message
    np.testing.assert_allclose(res.q[:, 0], 0.5235987755982988 + W * res.t, rtol=0, atol=1e-12)
    # The rider moves and the crank does work by visible amounts...
    assert np.ptp(res.q[:, 1]) > 0.01 and np.ptp(res.energy.work) > 0.05
    # ...and T + V - W stays put to the integrator's accuracy (2e-12 J measured in the Rust test).
    assert np.abs(res.energy.balance).max() < 1e-10
    # The crank torque is inverse dynamics' for the motion found, the rider needing none.
    tau = mech.inverse_dynamics(res.q[50], res.qd[50], res.qdd[50])
    np.testing.assert_allclose(tau, [res.tau[50, 0], 0.0], rtol=0, atol=1e-8)
    # The model the result carries keeps its motion: the same run again, to the last bit.
    again = pd.from_dict(res.metadata["model"]).simulate(2.0, output_dt=0.01, rtol=1e-10, atol=1e-13)
    np.testing.assert_array_equal(again.tau, res.tau)


def test_api_motion_replaces_the_model_files(pendulum):
    mech = pd.from_dict(SHAKER)
    res = mech.simulate(0.5, output_dt=0.1, motion={"phi": 0.0})
    assert np.all(res.q[:, 0] == res.q[0, 0])
    assert res.metadata["settings"]["motion"] == {"phi": 0.0}


@pytest.mark.parametrize(("motion", "error", "match"), [
    ({"crank": 1.0}, ValueError, "unknown coordinate 'crank'; coordinates are: theta"),
    ({"theta": {"t": [0, 1]}}, ValueError, r"a table is \{'t': times, 'q': positions\}"),
    ({"theta": {"t": [0, 1, 1], "q": [0, 1, 2]}}, ValueError, r"t\[2\] = 1 does not come after"),
    ({"theta": "fast"}, TypeError, "give a speed"),
    ({"theta": math.inf}, ValueError, "must be finite"),
    ({"theta": {"t": [0, 0.5], "q": [0, 1]}}, pd.SimulationError, "extend the table or shorten t_end"),
])
def test_bad_motions_are_refused_with_the_fix(pendulum, motion, error, match):
    with pytest.raises(error, match=match):
        pendulum.simulate(1.0, motion=motion)


def test_a_failing_motion_function_ends_the_run_with_its_error(pendulum):
    def broken(t):
        if t > 0.2:
            raise RuntimeError("no data past 0.2 s")
        return W * t, W, 0.0

    res = pendulum.simulate(1.0, motion={"theta": broken})
    assert res.status == "drive_failed" and "no data past 0.2 s" in res.message
    assert 0.0 < res.t[-1] <= 0.2


def test_a_motion_function_of_the_wrong_shape_is_named(pendulum):
    res = pendulum.simulate(1.0, motion={"theta": lambda t: (W * t, W)})
    assert res.status == "drive_failed" and len(res.t) == 0
    assert "the motion function of 'theta' must return (q, qd, qdd), three numbers" in res.message


def test_model_file_motion_error_names_file_field_and_fix(tmp_path):
    d = pendulum_dict()
    d["drives"] = [{"coordinate": "theta", "motion": {"speed": 1.0, "table": {"t": [0, 1], "q": [0, 1]}}}]
    path = tmp_path / "pendulum.json"
    path.write_text(json.dumps(d))
    with pytest.raises(pd.ModelError, match=r"pendulum.json: drives\[0\].motion: give exactly one of `speed`"):
        pd.load(path)


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "planardyn", *map(str, args)], capture_output=True, text=True,
                          timeout=120)


def test_cli_speed_option(tmp_path):
    model = tmp_path / "pendulum.json"
    model.write_text(json.dumps(pendulum_dict()))
    out = tmp_path / "run.npz"
    p = run_cli("simulate", model, "--speed", "theta=60rpm", "--t-end", "0.5", "--output-dt", "0.05", "-o", out)
    assert p.returncode == 0, p.stderr
    res = read_results(out)
    # 60 rpm = 2 pi rad/s.
    np.testing.assert_allclose(res.qd[:, 0], W, rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.tau[:, 0], MGL * np.sin(W * res.t), rtol=0, atol=1e-11)
    assert res.metadata["settings"]["motion"] == {"theta": pytest.approx(W)}
    for bad, said in [("theta=1m/s", "is a rate of a displacement, but the coordinate is an angle: use rad/s"),
                      ("theta=fast", "is not a rate: give a number and one of rad/s, rev/s, rpm, deg/s"),
                      ("crank=1rpm", "give NAME=RATE with NAME one of theta")]:
        p = run_cli("simulate", model, "--speed", bad)
        assert p.returncode == 2 and f"--speed {bad}: " in p.stderr and said in p.stderr, p.stderr


def test_cli_speed_given_twice_is_refused(tmp_path):
    # It used to run with the last one silently (s15-sweep).
    model = tmp_path / "pendulum.json"
    model.write_text(json.dumps(pendulum_dict()))
    code, err = cli_run("simulate", model, "--speed", "theta=1", "--speed", "theta=2", "-o", tmp_path / "run.npz")
    assert code == 2 and "--speed theta=2: theta already has a speed: give each coordinate's --speed once" in err, err
    assert not (tmp_path / "run.npz").exists()


@pytest.mark.parametrize(("text", "kind", "si"), [
    ("1rev/s", "angle", 2 * math.pi), ("90 deg/s", "angle", math.pi / 2), ("-30rpm", "angle", -math.pi),
    ("2.5", "angle", 2.5), ("1e-1m/s", "displacement", 0.1), ("250mm/s", "displacement", 0.25),
])
def test_rates_convert_to_si(text, kind, si):
    from planardyn.units import parse_rate

    assert parse_rate(text, kind) == pytest.approx(si, rel=1e-15)
