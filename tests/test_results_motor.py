"""A geared model's results carry its motor torques (``tau_motor``), through results files, to
identification: what the drives of a robot with transmissions measure."""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json

import numpy as np
import planardyn as pd
import pytest
from conftest import cli_run
from planardyn import batch, cli
from planardyn.identify import base_parameters
from test_identify import excitation
from test_regressor_losses import drive_law_torques, geared_five_bar


@pytest.fixture(scope="module")
def run():
    # The geared five-bar (ratio 10, efficiency 0.9, motor and pin friction) moved through a
    # two-tone motion of both cranks, as tests/test_identify.py moves the bare five-bar.
    mech = geared_five_bar()
    motion = excitation(mech.q0)
    res = mech.simulate(t_end=2.0, output_dt=0.005, motion=motion)
    assert res.success, res.message
    return mech, res


def test_a_runs_motor_torques_are_its_drives_laws():
    # Under the model's drives (motor-side laws: a constant and a table) the result's motor
    # torques are the laws' values: tau is the joint side they produce (the gears' outputs),
    # and motor_torques maps it back with the rotors' torques (both gear branches occur;
    # round-off 1e-15 of the efforts, bound 1e-12) wherever the gear is not held: at rest
    # (|n qd| <= stiction_speed, 1 rad/s here) a gear that sticks (its speed decaying as
    # qdd = -qd / 0.01 s, docs/actuators.md) holds with any motor torque between its two
    # branches', and the motoring one is reported (4 of the 404 values here); forward dynamics
    # with it gives the run's accelerations back all the same.
    mech = geared_five_bar()
    res = mech.simulate(t_end=0.5, output_dt=0.005, qd0=[1.0, -0.8])
    assert res.success, res.message
    t_m = drive_law_torques(mech, res.t)
    held = (np.abs(10.0 * res.qd) <= 1.0) & (np.abs(res.qdd + res.qd / 0.01) <= 1e-9 * np.abs(res.qdd).max())
    assert 0 < np.count_nonzero(held) <= 8
    np.testing.assert_allclose(res.tau_motor[~held], t_m[~held], rtol=0, atol=1e-12 * np.abs(t_m).max())
    for i in np.nonzero(held.any(axis=1))[0]:
        qdd = mech.forward_dynamics(res.q[i], res.qd[i], tau=res.tau_motor[i])
        np.testing.assert_allclose(qdd, res.qdd[i], rtol=1e-9, atol=1e-9)
    # The joint side is ~n eta (or n / eta) times larger: the two are not the same column.
    assert np.abs(res.tau).max() > 8 * np.abs(res.tau_motor).max()
    assert np.any(res.tau * res.qd > 0) and np.any(res.tau * res.qd < 0)
    # A batch run is the same run, motor torques included.
    same = batch.simulate([(mech, {"qd0": [1.0, -0.8]})], t_end=0.5, output_dt=0.005)[0]
    np.testing.assert_array_equal(same.tau_motor, res.tau_motor)


@pytest.mark.parametrize("ext", [".csv", ".parquet", ".npz"])
def test_results_files_keep_the_motor_torques(run, tmp_path, ext):
    mech, res = run
    back = pd.read_results(res.save(tmp_path / f"run{ext}"))
    # Files hold every double exactly; the motor torques are motor_torques of the rows read
    # back (the same function of the same numbers: 0 difference).
    np.testing.assert_array_equal(back.tau_motor, res.tau_motor)
    again = mech.motor_torques(back.q, back.qd, back.qdd, back.tau, x=back.x, xd=back.xd, allow_singular=True)
    np.testing.assert_array_equal(back.tau_motor, again)
    np.testing.assert_array_equal(back.tau, res.tau)
    frame = back.to_dataframe()
    np.testing.assert_array_equal(frame["tau_motor_theta2"].to_numpy(), res.tau_motor[:, 1])
    # A table keeps the rows: taking every other row keeps their motor torques.
    np.testing.assert_array_equal(res.take(np.arange(0, len(res), 2)).tau_motor, res.tau_motor[::2])


def test_a_model_without_actuators_has_no_motor_columns(tmp_path):
    mech = pd.load_example("five-bar")
    res = mech.simulate(t_end=0.1, output_dt=0.01)
    assert res.tau_motor is None
    path = res.save(tmp_path / "run.csv")
    header = next(line for line in path.read_text().splitlines() if not line.startswith("#"))
    assert "tau_motor" not in header and header.split(",")[-1] == "phid_distal_right"
    assert pd.read_results(path).tau_motor is None


def test_identify_command_reads_a_geared_runs_motor_torques(run, tmp_path):
    # The run's results file with 1 % noise (of each motor's RMS) on its motor torques, what
    # the drives would measure: `planardyn identify` recovers every base parameter of the
    # model within 3 of its standard errors (measured: largest |z| 1.69 of 21; fitting the
    # joint-side tau instead puts one 186 standard errors off).
    mech, res = run
    rng = np.random.default_rng(5)
    t_m = res.tau_motor + 0.01 * np.sqrt(np.mean(res.tau_motor**2, axis=0)) * rng.standard_normal(res.tau.shape)
    data = dataclasses.replace(res, tau_motor=t_m).save(tmp_path / "measured.npz")
    model = tmp_path / "geared.json"
    model.write_text(json.dumps(mech.to_dict()))
    out = tmp_path / "found.json"
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert cli.main(["identify", str(model), str(data), "-o", str(out)]) == 0
    found = json.loads(out.read_text())
    base = base_parameters(mech)
    assert found["base_parameters"] == base.expressions and found["samples"] == len(res.t)
    truth = base.of(mech.regressor_parameters)
    z = (np.array(found["identified"]) - truth) / np.array(found["std_error"])
    assert np.all(np.abs(z) <= 3), z
    # Without the noise the file's motor torques give the model's base parameters: least
    # squares of exact rows (the regressor is exact at the model's parameters to 1e-13 of the
    # efforts, tests/test_regressor_losses.py), measured 3.0e-13 off at worst, bound 1e-10.
    exact = tmp_path / "exact.csv"
    res.save(exact)
    with contextlib.redirect_stdout(io.StringIO()):
        assert cli.main(["identify", str(model), str(exact), "-o", str(out)]) == 0
    np.testing.assert_allclose(json.loads(out.read_text())["identified"], truth, rtol=0, atol=1e-10)
    # The joint-side efforts instead (a file without the motor torques) are refused, naming the fix.
    old = dataclasses.replace(res, tau_motor=None).save(tmp_path / "old.npz")
    code, err = cli_run("identify", model, old)
    assert code == 2 and "tau_motor" in err and "joint-side" in err


def test_a_geared_runs_point_motion_is_its_own(run):
    # Along a result the body accelerations (and reactions) come from forward dynamics of each
    # row under the run's drives: with motors their torques, not res.tau (the gears' output).
    # The crank tip C1, 0.25 m from A1 at angle theta1: a = 0.25 (theta1'' perp - theta1'^2 e),
    # from the run's own theta1, theta1', theta1'' (to the 1e-9 of the fixed point's round-off).
    mech, res = run
    _, _, a = mech.point_motion(res)["C1"]
    th, w, al = res.q[:, 0], res.qd[:, 0], res.qdd[:, 0]
    e, perp = np.column_stack([np.cos(th), np.sin(th)]), np.column_stack([-np.sin(th), np.cos(th)])
    expected = 0.25 * (al[:, None] * perp - (w**2)[:, None] * e)
    np.testing.assert_allclose(a, expected, rtol=0, atol=1e-9 * np.abs(expected).max())
