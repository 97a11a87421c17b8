"""The Python API: loading, closed forms, consistency, errors, callbacks, results.

Expected values come from closed forms of the models in conftest.py (each test says which),
or from another entry point of the same library (consistency: forward then inverse).
"""

from __future__ import annotations

import copy
import json
import math
import os
import re
import signal
import threading

import numpy as np
import planardyn as pd
import pytest
import yaml
from conftest import (
    FOUR_BAR_A,
    FOUR_BAR_THETA0,
    MODELS,
    PENDULUM_I,
    PENDULUM_L,
    PENDULUM_M,
    G,
    four_bar_B,
    four_bar_dict,
    pendulum_dict,
    shipped_models,
)
from hypothesis import given, settings
from hypothesis import strategies as st

# Round-off level for closed forms evaluated in a few dozen flops on O(1) numbers.
CLOSED_FORM_RTOL = 1e-12
# Forward then inverse dynamics solve the same linear system twice (Cholesky of A, condition
# number O(10) here): the required 1e-9 leaves three orders of magnitude of margin.
ROUND_TRIP_RTOL = 1e-9
# Positions: Newton stops at a scaled residual of 1e-12 (kinematics/position.rs POSITION_TOL).
POSITION_ATOL = 1e-11


# ------------------------------------------------------------------ loading


@pytest.mark.parametrize("path", shipped_models(), ids=lambda p: p.name)
def test_every_shipped_model_loads_and_simulates(path):
    mech = pd.load(path)
    m, n = mech.dof, mech.n_bodies
    assert m == len(mech.coordinate_names) >= 1
    assert mech.source == str(path)
    assert mech.q0.shape == (m,) and mech.x0.shape == (3 * n,)
    A = mech.mass_matrix(mech.q0)
    assert A.shape == (m, m)
    np.testing.assert_allclose(A, A.T, rtol=0, atol=1e-14 * np.abs(A).max())
    assert np.all(np.linalg.eigvalsh(A) > 0)
    res = mech.simulate()
    assert res.success, res.message
    N = len(res.t)
    assert N >= 2
    for name, arr, shape in [
        ("q", res.q, (N, m)), ("qd", res.qd, (N, m)), ("qdd", res.qdd, (N, m)), ("tau", res.tau, (N, m)),
        ("x", res.x, (N, 3 * n)), ("xd", res.xd, (N, 3 * n)), ("poses", res.poses, (N, n, 3)),
        ("sigma", res.sigma, (N,)), ("residual", res.residual, (N,)), ("partitioned", res.partitioned, (N,)),
        ("kinetic", res.energy.kinetic, (N,)), ("balance", res.energy.balance, (N,)),
    ]:
        assert arr.shape == shape, name
        assert not np.isnan(arr.astype(float)).any(), name
    assert res.t[0] == 0.0 and res.t[-1] == pytest.approx(mech.simulate_defaults["t_end"] or 1.0)


def test_from_dict_equals_load():
    # The same file read by the Rust YAML parser and by PyYAML gives the same mechanism.
    path = MODELS / "four-bar-gravity.yaml"
    if not path.exists():
        pytest.skip("four-bar-gravity.yaml is not there")
    by_file = pd.load(path)
    by_dict = pd.from_dict(yaml.safe_load(path.read_text()))
    assert by_dict == by_file
    assert by_dict.source == "<dict>"
    q = by_file.q0 + 0.3
    np.testing.assert_array_equal(by_dict.mass_matrix(q), by_file.mass_matrix(q))
    # and to_dict() round-trips
    assert pd.from_dict(by_file.to_dict()) == by_file


def test_loads_json_and_yaml_agree():
    import json

    d = four_bar_dict()
    a = pd.loads(json.dumps(d), format="json")
    b = pd.loads(yaml.safe_dump(d, sort_keys=False), format="yaml")
    assert a == b
    assert a.source == "<string>"


def test_description(four_bar):
    m = four_bar
    assert m.name == "crank-rocker four-bar"
    assert m.coordinate_names == ["theta"] and m.coordinate_kinds == ["angle"]
    assert m.body_names == ["crank", "coupler", "rocker"]
    assert m.pair_names == ["crank_pivot", "elbow", "wrist", "rocker_pivot"]
    assert m.point_names == ["O", "A", "B", "D"] and m.ground_points == ["O", "D"]
    np.testing.assert_array_equal(m.masses, [0.3, 1.0, 0.8])
    # uniform bar: I = m L^2 / 12 with L = 0.3, 1.0, 0.8 m (the drawn lengths)
    np.testing.assert_allclose(m.inertias, [0.3 * 0.09 / 12, 1.0 / 12, 0.8 * 0.64 / 12], rtol=CLOSED_FORM_RTOL)
    np.testing.assert_array_equal(m.gravity, [0.0, -G])
    assert m.q0[0] == FOUR_BAR_THETA0 and m.qd0[0] == 0.0
    assert m.pairs[1] == {"name": "elbow", "kind": "revolute", "bodies": ("crank", "coupler"), "point": "A", "axis": None,
                          "rows": (2, 4)}
    assert [p for p, _ in m.body_points[2]] == ["D", "B"]
    assert "crank-rocker" in repr(m) and "1 dof" in repr(m)


def test_exception_tree():
    assert issubclass(pd.ModelError, pd.PlanardynError) and issubclass(pd.ModelError, ValueError)
    for e in (pd.AssemblyError, pd.SingularityError, pd.SimulationError):
        assert issubclass(e, pd.PlanardynError) and not issubclass(e, ValueError)


# ------------------------------------------------------------------ model errors


def _model_error(d: dict) -> pd.ModelError:
    with pytest.raises(pd.ModelError) as info:
        pd.from_dict(d)
    return info.value


def test_unknown_body_in_pair_names_the_field():
    d = four_bar_dict()
    d["pairs"][0]["bodies"][1] = "cranck"
    e = _model_error(d)
    assert "pairs[0].bodies[1]" in str(e) and "cranck" in str(e)
    assert e.path == "pairs[0].bodies[1]" and e.source == "<dict>"


def test_negative_mass_names_the_field():
    d = four_bar_dict()
    d["bodies"]["coupler"]["mass"] = -1.0
    e = _model_error(d)
    assert "bodies.coupler.mass" in str(e)


def test_wrong_number_of_coordinates_names_mobility():
    d = four_bar_dict()
    d["coordinates"].append({"name": "psi", "pair": "rocker_pivot", "value": 0.0})
    e = _model_error(d)
    assert "coordinates" in str(e) and "mobility" in str(e)


def test_malformed_yaml():
    with pytest.raises(pd.ModelError) as info:
        pd.loads("name: x\npoints: {A: [0, 0]\n", source="broken.yaml")
    assert "broken.yaml" in str(info.value)


def _yaml_error(text: str) -> pd.ModelError:
    with pytest.raises(pd.ModelError) as info:
        pd.loads(text, source="m.yaml")
    return info.value


def test_a_hexadecimal_mass_is_named_as_such():
    # YAML reads 0x10 as the integer 16; a number field takes decimal numbers only.
    d = four_bar_dict()
    d["bodies"]["crank"]["mass"] = "MASS"
    e = _yaml_error(yaml.safe_dump(d, sort_keys=False).replace("MASS", "0x10"))
    assert e.path == "bodies.crank.mass"
    assert "the integer 16 is written in hexadecimal, octal or binary (0x, 0o or 0b)" in str(e)
    assert str(e).endswith("; write the decimal number 16")


def test_a_yaml_tag_is_refused_with_its_line_and_column():
    e = _yaml_error("!model\n" + yaml.safe_dump(four_bar_dict(), sort_keys=False))
    assert e.path == "line 1 column 1"
    assert str(e) == (
        "m.yaml: line 1 column 1: the YAML tag `!model` is not part of the model format; "
        "remove it and write the value alone (see `planardyn docs model-format`)"
    )


def test_wrong_type_names_the_field():
    d = four_bar_dict()
    d["bodies"]["crank"]["mass"] = "heavy"
    e = _model_error(d)
    assert "bodies.crank.mass" in str(e)


def test_missing_file_is_a_model_error(tmp_path):
    with pytest.raises(pd.ModelError, match="nothere.yaml"):
        pd.load(tmp_path / "nothere.yaml")


def test_a_refused_format_names_every_format_accepted():
    # The refusal listed 'yaml' and 'json' while "data" (from_dict's JSON) was accepted too; each
    # format it names now loads the four-bar's JSON (YAML reads JSON), and nothing else is named.
    with pytest.raises(pd.ArgumentError) as refused:
        pd.loads("{}", format="toml")
    named = re.findall(r"'(\w+)'", str(refused.value).split(", got")[0])
    assert named == ["yaml", "json", "data"], str(refused.value)
    text = json.dumps(four_bar_dict())
    for fmt in named:
        assert pd.loads(text, format=fmt).dof == 1, fmt


def test_bad_format_and_bad_dict():
    with pytest.raises(ValueError, match="format"):
        pd.loads("{}", format="toml")
    with pytest.raises(TypeError):
        pd.from_dict([1, 2])


# ------------------------------------------------------------------ pendulum closed forms


def test_pendulum_mass_matrix_and_bias(pendulum):
    # A = I_O = I + m l^2 (parallel axes); qdd = b / A with b = -m g l sin q (formulation.md).
    I_O = PENDULUM_I + PENDULUM_M * PENDULUM_L**2
    for q in (0.0, 0.4, -1.3, 2.9):
        np.testing.assert_allclose(pendulum.mass_matrix([q]), [[I_O]], rtol=CLOSED_FORM_RTOL)
        for qd in (0.0, 3.0):
            qdd = pendulum.forward_dynamics([q], [qd])
            b = -PENDULUM_M * G * PENDULUM_L * math.sin(q)
            assert qdd[0] == pytest.approx(b / I_O, rel=CLOSED_FORM_RTOL, abs=1e-15)
    # with an effort tau the balance is I_O qdd = b + tau
    qdd = pendulum.forward_dynamics([0.4], [0.0], tau=[2.0])
    assert qdd[0] == pytest.approx((-PENDULUM_M * G * PENDULUM_L * math.sin(0.4) + 2.0) / I_O, rel=CLOSED_FORM_RTOL)


def test_pendulum_energy_and_positions(pendulum):
    # T = 1/2 I_O qd^2; V = m g y_c with y_c = -l cos q; centre of mass at l (sin q, -cos q).
    I_O = PENDULUM_I + PENDULUM_M * PENDULUM_L**2
    q, qd = 0.7, -1.9
    T, V = pendulum.energy([q], [qd])
    assert T == pytest.approx(0.5 * I_O * qd**2, rel=CLOSED_FORM_RTOL)
    assert V == pytest.approx(-PENDULUM_M * G * PENDULUM_L * math.cos(q), rel=CLOSED_FORM_RTOL)
    x = pendulum.assemble([q])
    np.testing.assert_allclose(x[:2], [PENDULUM_L * math.sin(q), -PENDULUM_L * math.cos(q)], atol=POSITION_ATOL)
    assert x[2] == pytest.approx(q - math.pi / 2, abs=POSITION_ATOL)  # body angle of O->A


def test_pendulum_reaction(pendulum):
    # At rest hanging straight down the pivot carries the weight: the ground exerts
    # (0, m g) on the bob, and a revolute pair carries no couple.
    r = pendulum.reactions([0.0], [0.0])
    np.testing.assert_allclose(r, [[0.0, PENDULUM_M * G, 0.0]], atol=1e-12)


def test_pendulum_small_oscillation_period(pendulum):
    # T0 = 2 pi sqrt(I_O / (m g l)); at amplitude q0 the period is T0 (1 + q0^2/16 + ...),
    # so q0 = 1e-4 rad is within 1e-9 of T0, far inside the 1e-6 asked.
    I_O = PENDULUM_I + PENDULUM_M * PENDULUM_L**2
    T0 = 2 * math.pi * math.sqrt(I_O / (PENDULUM_M * G * PENDULUM_L))
    res = pendulum.simulate(t_end=5.5 * T0, q0=[1e-4], rtol=1e-12, atol=1e-16, output_dt=T0 / 400)
    assert res.success, res.message
    q, t = res.q[:, 0], res.t
    down = np.nonzero((q[:-1] > 0) & (q[1:] <= 0))[0]  # downward zero crossings
    # linear interpolation at the crossing (q'' = 0 there, so the error is third order in the spacing)
    tc = t[down] - q[down] * (t[down + 1] - t[down]) / (q[down + 1] - q[down])
    # released at the right extreme: crossings at T0/4 + k T0, k = 0..5, within 5.5 T0
    assert len(tc) == 6
    period = (tc[-1] - tc[0]) / (len(tc) - 1)
    assert period == pytest.approx(T0, rel=1e-6)


# ------------------------------------------------------------------ four-bar


# Crank angles within 1.5 rad of the drawing either way (farther: the test after this one).
NEAR_DRAWING = st.floats(FOUR_BAR_THETA0 - 1.5, FOUR_BAR_THETA0 + 1.5)


@given(theta=NEAR_DRAWING)
@settings(max_examples=40, deadline=None)
def test_four_bar_positions_match_closed_form(theta):
    # B from the circle intersection (conftest.four_bar_B); A = a (cos q, sin q).
    _check_four_bar_position(theta)


@pytest.mark.parametrize("theta", [-1.0, -4.0, 8.0, 20.0])
def test_four_bar_far_from_drawing_stays_on_branch(theta):
    # Continuation in bounded steps keeps the drawn assembly mode, even several turns away.
    _check_four_bar_position(theta)


def _check_four_bar_position(theta):
    mech = _FOUR_BAR
    x = mech.assemble([theta])
    pts = mech.point_positions(x)
    names = mech.point_names
    np.testing.assert_allclose(pts[names.index("A")], [FOUR_BAR_A * math.cos(theta), FOUR_BAR_A * math.sin(theta)], atol=POSITION_ATOL)
    np.testing.assert_allclose(pts[names.index("B")], four_bar_B(theta), atol=POSITION_ATOL)


_FOUR_BAR = pd.from_dict(four_bar_dict())


def test_forward_then_inverse_returns_tau(four_bar):
    # tau -> forward dynamics -> qdd -> inverse dynamics -> tau (consistency).
    for q, qd, tau in [(1.0, 0.0, 2.0), (-2.5, 4.0, -0.7), (3.3, -6.0, 0.0), (10.0, 1.5, 5.0)]:
        qdd = four_bar.forward_dynamics([q], [qd], tau=[tau])
        back = four_bar.inverse_dynamics([q], [qd], qdd)
        assert back.shape == (1,)
        assert back[0] == pytest.approx(tau, rel=ROUND_TRIP_RTOL, abs=ROUND_TRIP_RTOL)


def test_inverse_dynamics_vectorised_along_a_trajectory(four_bar):
    # A run under a time-varying drive records (q, qd, qdd, tau) at each output; the (N, m)
    # inverse dynamics must give tau back row by row (continuation along the rows).
    res = four_bar.simulate(t_end=2.0, drives=lambda t, q, qd: [1.5 + np.sin(3.0 * t)], output_dt=0.01)
    assert res.success, res.message
    assert np.ptp(res.q[:, 0]) > 2 * math.pi  # the crank turns over: a real test of the continuation
    tau = four_bar.inverse_dynamics(res.q, res.qd, res.qdd)
    assert tau.shape == res.tau.shape == (len(res.t), 1)
    # tau = A qdd - b cancels terms far larger than tau here (qdd reaches ~1e3 rad/s^2):
    # measure the error against the largest generalized inertia force A qdd of the run.
    A_max = max(four_bar.mass_matrix([th])[0, 0] for th in np.linspace(0, 2 * math.pi, 17))
    force_scale = A_max * np.abs(res.qdd).max()
    np.testing.assert_allclose(tau, res.tau, rtol=0, atol=ROUND_TRIP_RTOL * force_scale)
    np.testing.assert_allclose(res.tau[:, 0], 1.5 + np.sin(3.0 * res.t), rtol=1e-15, atol=1e-15)


def test_velocity_analogues_match_finite_differences(four_bar):
    # u = dx/dq: central differences of the position solution, error O(h^2) ~ 1e-10.
    q, h = 0.8, 1e-5
    k = four_bar.kinematics([q], qd=[2.0])
    fd = (four_bar.assemble([q + h]) - four_bar.assemble([q - h])) / (2 * h)
    np.testing.assert_allclose(k["u"][:, :, 0].ravel(), fd, atol=1e-8)
    fd2 = (four_bar.assemble([q + h]) - 2 * four_bar.assemble([q]) + four_bar.assemble([q - h])) / h**2
    np.testing.assert_allclose(k["w"][:, :, 0, 0].ravel(), fd2, atol=1e-4)
    # xd = U qd and c = qd^2 w for one coordinate
    np.testing.assert_allclose(k["xd"], 2.0 * k["u"][:, :, 0].ravel(), rtol=1e-14)
    np.testing.assert_allclose(k["c"], 4.0 * k["w"][:, :, 0, 0].ravel(), rtol=1e-12, atol=1e-14)
    n = four_bar.n_bodies
    assert k["poses"].shape == (n, 3) and k["u"].shape == (n, 3, 1) and k["w"].shape == (n, 3, 1, 1)
    assert k["points"].shape == (4, 2) and k["point_velocities"].shape == (4, 2)
    assert 0 < k["sigma_min"] <= k["sigma_passive"] and k["residual"] < 1e-12
    # the ground points do not move
    np.testing.assert_array_equal(k["point_velocities"][[0, 3]], 0.0)


def test_assembly_error_out_of_reach():
    # Drive the four-bar at its rocker instead. |OB|^2 = d^2 + c^2 + 2 c d cos(psi) must lie
    # in [(b - a)^2, (b + a)^2] = [0.49, 1.69]; at psi = 0 it is 2.89: B is out of reach.
    d = four_bar_dict()
    Bx, By = four_bar_B(FOUR_BAR_THETA0)
    psi0 = math.atan2(By, Bx - 0.9)  # absolute angle of D->B in the drawing
    d["coordinates"] = [{"name": "psi", "pair": "rocker_pivot", "value": psi0}]
    d["drives"] = []
    mech = pd.from_dict(d)
    mech.assemble([psi0 + 0.1])  # reachable (psi0 is near the limit cos(psi) = 1/6)
    # on the way the continuation meets the limit position (crank and coupler in line),
    # where the rocker stops determining the mechanism: either error may come first.
    with pytest.raises((pd.AssemblyError, pd.SingularityError)) as info:
        mech.assemble([0.0])
    assert "try" in str(info.value) or "singular" in str(info.value)


def test_shape_errors(four_bar):
    with pytest.raises(ValueError, match=r"q must have shape \(1,\)"):
        four_bar.assemble([0.1, 0.2])
    with pytest.raises(ValueError, match="not a finite"):
        four_bar.mass_matrix([np.nan])
    with pytest.raises(ValueError, match="same shape"):
        four_bar.inverse_dynamics(np.zeros((3, 1)), np.zeros((2, 1)), np.zeros((3, 1)))
    with pytest.raises(ValueError, match=r"\(N, 1\)"):
        four_bar.inverse_dynamics(np.zeros((3, 2)), np.zeros((3, 2)), np.zeros((3, 2)))
    with pytest.raises(ValueError, match="t_end"):
        four_bar.simulate(t_end=-1.0)


# ------------------------------------------------------------------ simulation


def test_callable_drive_equals_model_drive(four_bar):
    # The model's constant drive (1.5 N m) and the same constant from Python give the same run.
    a = four_bar.simulate(t_end=0.5)
    b = four_bar.simulate(t_end=0.5, drives=lambda t, q, qd: np.array([1.5]))
    assert a.success and b.success
    np.testing.assert_array_equal(a.t, b.t)
    np.testing.assert_allclose(b.q, a.q, rtol=0, atol=1e-14)


def test_raising_drive_gives_drive_failed_and_partial_trajectory(four_bar):
    def drive(t, q, qd):
        if t > 0.3:
            raise RuntimeError("motor overheated")
        return [1.5]

    res = four_bar.simulate(t_end=1.0, drives=drive)
    assert not res.success and res.status == "drive_failed"
    assert "motor overheated" in res.message
    assert len(res.t) > 10 and 0.2 < res.t[-1] <= 0.3
    assert not np.isnan(res.q).any()


def test_drive_returning_wrong_shape(four_bar):
    # wrong from the start: a failed run with nothing computed, and the reason
    res = four_bar.simulate(t_end=0.2, drives=lambda t, q, qd: [1.0, 2.0])
    assert res.status == "drive_failed" and "shape" in res.message and len(res.t) == 0
    # wrong later: the run ends there
    res = four_bar.simulate(t_end=0.2, drives=lambda t, q, qd: [1.0] if t < 0.1 else [1.0, 2.0])
    assert res.status == "drive_failed" and "shape" in res.message and res.t[-1] <= 0.1


def test_progress_is_called_and_can_cancel(four_bar):
    seen = []
    res = four_bar.simulate(t_end=1.0, progress=seen.append, output_dt=0.001)
    assert res.success
    assert 10 <= len(seen) <= 110 and seen == sorted(seen) and seen[-1] <= 1.0

    def stop_early(t):
        return t < 0.25

    res = four_bar.simulate(t_end=1.0, progress=stop_early)
    assert res.status == "cancelled" and not res.success
    assert 0.25 <= res.t[-1] < 0.5

    def boom(t):
        raise ValueError("enough")

    res = four_bar.simulate(t_end=1.0, progress=boom)
    assert res.status == "cancelled" and "enough" in res.message


def test_too_many_steps(four_bar):
    res = four_bar.simulate(t_end=1.0, max_steps=5)
    assert res.status == "too_many_steps" and len(res.t) >= 1


def test_hopeless_run_stops_early_with_its_last_state():
    # 1e12 N m on both motors of the five-bar: the steps shrink as 1/t, and the run used its
    # 1e7 attempts (293 s) to reach t = 0.0035 s, returning the t = 0 row alone. It is judged
    # after 10,000 attempts (mean step ~1e-9 s < t_end / (10 max_steps) = 1e-8 s).
    mech = pd.load(MODELS / "five-bar.yaml")
    res = mech.simulate(t_end=1.0, output_dt=0.01, drives=lambda t, q, qd: [1e12, 1e12])
    assert res.status == "step_size_too_small" and not res.success
    assert "efforts or rates are too large" in res.message and "max_steps" in res.message
    attempts = res.stats["naccept"] + res.stats["nreject"]
    # The file's DOPRI5 (FSAL): 6 evaluations per attempt, 2 more at each (re)start.
    starts = 1 + res.stats["chart_switches"]
    assert 10_000 <= attempts < 10_100 and res.stats["nfev"] <= 6 * attempts + 2 * starts
    # The t = 0 output and the last accepted state, with its real energy balance.
    assert len(res.t) == 2 and 0 < res.t[-1] < 1e-8 * attempts
    drift = abs(res.energy.balance[-1])
    assert np.isfinite(res.q[-1]).all() and np.isfinite(drift)
    assert res.stats["energy_drift"] == pytest.approx(drift, rel=1e-12)


def test_simulation_option_errors(four_bar):
    with pytest.raises(pd.SimulationError, match="unknown integration method"):
        four_bar.simulate(method="euler")
    with pytest.raises(pd.SimulationError, match="rk4"):
        four_bar.simulate(method="rk4")
    with pytest.raises(pd.SimulationError, match="rtol"):
        four_bar.simulate(rtol=-1.0)
    res = four_bar.simulate(t_end=0.1, method="rk4", dt=1e-3)
    assert res.success


def test_t_eval_and_initial_state(four_bar):
    t_eval = np.linspace(0.0, 0.5, 11)
    res = four_bar.simulate(t_end=0.5, t_eval=t_eval, q0=[0.2], qd0=[3.0])
    np.testing.assert_array_equal(res.t, t_eval)
    assert res.q[0, 0] == pytest.approx(0.2, abs=1e-12) and res.qd[0, 0] == pytest.approx(3.0, rel=1e-12)


def test_energy_balance_of_passive_pendulum(pendulum):
    # No drive, no damping: T + V is constant (formulation.md, "useful exact checks").
    res = pendulum.simulate(t_end=3.0, q0=[1.2], rtol=1e-11, atol=1e-13)
    e = res.energy
    np.testing.assert_allclose(e.total, e.total[0], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(e.work, 0.0)
    assert e.drift < 1e-9 and res.stats["energy_drift"] == pytest.approx(e.drift, rel=1e-6, abs=1e-15)


def test_result_table(four_bar, tmp_path):
    res = four_bar.simulate(t_end=0.3, output_dt=0.1)
    assert len(res) == 4
    cols = ["t", "theta", "qd_theta", "qdd_theta", "tau_theta", "kinetic", "potential", "work", "sigma"]
    df = res.to_dataframe()
    assert df.index.name == "t" and list(df.columns) == [*cols[1:], "power_theta"] and len(df) == 4
    np.testing.assert_array_equal(df["theta"].to_numpy(), res.q[:, 0])
    # to_csv and save write the results file that read_results, plot and animate read.
    path = res.to_csv(tmp_path / "r.txt")
    rows = [line for line in path.read_text().splitlines() if not line.startswith("#")]
    assert rows[0].split(",")[: len(cols) + 2] == [*cols, "residual", "partitioned"] and len(rows) == 5
    back = pd.read_results(res.save(tmp_path / "r.csv"))
    for name in ("t", "q", "qd", "qdd", "tau", "x", "xd", "sigma"):
        np.testing.assert_array_equal(getattr(back, name), getattr(res, name))  # full precision
    assert back.metadata["settings"] == res.metadata["settings"]
    with pytest.raises(ValueError, match="unknown results format '.txt'"):
        res.save(tmp_path / "r.txt")
    assert "status='success'" in repr(res) and "N=4" in repr(res)
    assert set(res.stats) >= {"nfev", "naccept", "nreject", "min_sigma", "energy_drift", "max_residual"}


def test_mechanism_is_immutable_and_hashable(four_bar):
    with pytest.raises(AttributeError):
        four_bar.name = "other"
    other = pd.from_dict(copy.deepcopy(four_bar_dict()))
    assert {four_bar, other} == {four_bar}
    assert pendulum_dict()["name"] != four_bar.name


def test_plot_helpers(four_bar):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from planardyn.plot import draw_mechanism, plot_coordinates, plot_efforts, plot_energy

    res = four_bar.simulate(t_end=0.2)
    fig, axes = plt.subplots(2, 2)
    before = dict(matplotlib.rcParams)
    assert len(plot_coordinates(res, ax=axes[0, 0])) == 1
    assert len(plot_efforts(res, ax=axes[0, 1])) == 1
    assert len(plot_energy(res, ax=axes[1, 0])) == 5
    artists = draw_mechanism(four_bar, res.x[-1], ax=axes[1, 1])
    assert len(artists) > 5
    assert dict(matplotlib.rcParams) == before
    plt.close(fig)


def test_stub_matches_native_module():
    # _core.pyi must declare exactly what the native module exposes (pydantic-core's check,
    # without mypy): top-level names and the Mechanism class's public members.
    import ast
    from pathlib import Path

    from planardyn import _core

    tree = ast.parse((Path(pd.__file__).parent / "_core.pyi").read_text())
    top, members = set(), set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            top.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            top.add(node.target.id)
        if isinstance(node, ast.ClassDef) and node.name == "Mechanism":
            members = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
    native = {n for n in dir(_core) if not n.startswith("_")} | {"__version__"}
    assert top == native
    assert members == {n for n in dir(_core.Mechanism) if not n.startswith("_")}


def test_mechanism_pickles(four_bar):
    import pickle

    again = pickle.loads(pickle.dumps(four_bar))
    assert again == four_bar and again.source == four_bar.source


def test_keyboard_interrupt_in_a_drive_propagates(four_bar):
    # A BaseException that is not an Exception (Ctrl-C) stops the run at once and is raised again.
    calls = []

    def drive(t, q, qd):
        calls.append(t)
        if t > 0.1:
            raise KeyboardInterrupt
        return [1.5]

    with pytest.raises(pd.SimulationInterrupted) as caught:
        four_bar.simulate(t_end=1.0, drives=drive, output_dt=0.01)
    assert sum(t > 0.1 for t in calls) == 1  # not retried with smaller steps
    # Still a KeyboardInterrupt, with the rows up to the last accepted step kept.
    res = caught.value.result
    assert isinstance(caught.value, KeyboardInterrupt) and res.status == "cancelled"
    assert 0.05 < res.t[-1] <= 0.1 and np.allclose(np.diff(res.t), 0.01, rtol=1e-9)
    assert np.isfinite(res.q).all() and "KeyboardInterrupt" in res.message


def test_ctrl_c_keeps_the_trajectory_so_far(four_bar):
    # A real SIGINT 0.3 s into a run of 1e4 s (over 60 s of work): the binding checks for
    # Ctrl-C every 0.1 s of wall time, well before the first 1 % of t_end (about 0.7 s), and
    # the result so far comes with the interrupt.
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(pd.SimulationInterrupted) as caught:
        four_bar.simulate(t_end=1e4, output_dt=0.01)
    timer.join()
    res = caught.value.result
    assert res.status == "cancelled" and not res.success and 0 < res.t[-1] < 100
    # The output grid up to the interrupt, then the last accepted state.
    assert np.allclose(np.diff(res.t[:-1]), 0.01, rtol=1e-9) and 0 < res.t[-1] - res.t[-2] <= 0.01
    assert np.isfinite(res.q).all()
    assert res.metadata["settings"]["t_end"] == 1e4


def test_redundant_constraints_load_with_a_warning_and_simulate():
    # A triple-crank parallelogram: Chebyshev-Grubler counts 3*4 - 2*6 = 0 freedoms, the
    # rank of its constraints shows 1; the loader keeps the independent rows and says which
    # pairs are redundant. Closed form: every crank turns alike, the coupler translates on a
    # circle of r = 0.3 m, so A = 3 m_k r^2/3 + m_c r^2 (uniform 0.3 kg cranks, 1 kg coupler).
    s = 0.2598076211353316
    model = {
        "name": "triple-crank parallelogram",
        "gravity": [0, -9.81],
        "points": {"O1": [0, 0], "O2": [0.5, 0], "O3": [1.0, 0], "A": [0.15, s], "B": [0.65, s], "C": [1.15, s]},
        "ground": ["O1", "O2", "O3"],
        "bodies": {
            "crank1": {"points": ["O1", "A"], "uniform_bar": ["O1", "A"], "mass": 0.3},
            "crank2": {"points": ["O2", "B"], "uniform_bar": ["O2", "B"], "mass": 0.3},
            "crank3": {"points": ["O3", "C"], "uniform_bar": ["O3", "C"], "mass": 0.3},
            "coupler": {"points": ["A", "C", "B"], "uniform_bar": ["A", "C"], "mass": 1.0},
        },
        "pairs": [
            {"type": "revolute", "name": n, "at": n, "bodies": ["ground", c]}
            for n, c in [("O1", "crank1"), ("O2", "crank2"), ("O3", "crank3")]
        ] + [
            {"type": "revolute", "name": n, "at": n, "bodies": [c, "coupler"]}
            for n, c in [("A", "crank1"), ("B", "crank2"), ("C", "crank3")]
        ],
        "coordinates": [{"name": "theta", "pair": "O1", "value": 1.0471975511965976}],
    }
    with pytest.warns(pd.PlanardynWarning, match="redundant constraints among pairs"):
        mech = pd.from_dict(model)
    assert len(mech.warnings) == 1
    A = mech.mass_matrix([0.4])
    assert A[0, 0] == pytest.approx(3 * 0.3 * 0.09 / 3 + 1.0 * 0.09, rel=1e-12)
    res = mech.simulate(t_end=0.3)
    assert res.success and res.energy.drift < 1e-8


def test_assembly_continues_from_a_given_start_on_its_branch(four_bar):
    # From a solution at theta = 2 (drawn branch), continuing to theta = 2.05 gives the
    # same body coordinates as the whole continuation from the drawing (both converge to
    # round-off on the same branch).
    x_far = four_bar.assemble([2.0])
    x_near = four_bar.assemble([2.05], x_start=x_far)
    np.testing.assert_allclose(x_near, four_bar.assemble([2.05]), atol=1e-12)
    kin = four_bar.kinematics([2.05], x_start=x_far)
    np.testing.assert_allclose(kin["x"], x_near, atol=1e-12)
    with pytest.raises(ValueError, match="x_start"):
        four_bar.assemble([2.0], x_start=[0.0, 1.0])


def test_singularity_error_carries_its_kind_and_no_made_up_sigma():
    """The five-bar drawn with its distal links in line (P on C1-C2) is a type II singularity:
    it loads (the pair constraints keep full rank), but inverse dynamics is undefined there.
    The factorisation that fails measures no singular value, so ``sigma_min`` is None."""
    text = pd.models.path("five-bar-free-fall").read_text()
    assert "P: [0.0, 0.32320508075688775]" in text
    mech = pd.loads(text.replace("P: [0.0, 0.32320508075688775]", "P: [0.0, 0.17320508075688773]"))
    q = np.array([[2.0943951023931953, 1.0471975511965976]])
    with pytest.raises(pd.SingularityError, match="type II") as info:
        mech.inverse_dynamics(q, np.zeros_like(q), np.zeros_like(q))
    assert info.value.kind == "type_ii"
    assert info.value.sigma_min is None
    assert "singular value" not in str(info.value)


# ---------------------------------------------------------------- issue 23 finding 6: NaN, inf and zero refused by name

def _three_legged_geared():
    from test_api_fuzz import GEARED

    return GEARED


@pytest.mark.parametrize(("call", "argument", "says"), [
    # Before: NaN efforts, infinite efforts.
    (lambda m: m.distribute_efforts(m.q0, [0, 0], [0, 0], method="preload", preload=[float("nan")]),
     "preload", "preload[0] = nan is not a finite number"),
    (lambda m: m.distribute_efforts(m.q0, [0, 0], [0, 0], method="preload", preload=[float("inf")]),
     "preload", "preload[0] = inf is not a finite number"),
    # Before: OverflowError (can't convert negative int to unsigned).
    (lambda m: m.available_torque(-1, [0.0]), "coordinate", "coordinate = -1 must be an integer from 0 to 2"),
    (lambda m: m.available_torque(3, [0.0]), "coordinate", "coordinate = 3 must be an integer from 0 to 2"),
], ids=["preload-nan", "preload-inf", "available-torque--1", "available-torque-3"])
def test_actuator_arguments_are_refused_by_name(call, argument, says):
    with pytest.raises(pd.ArgumentError) as info:
        call(_three_legged_geared())
    assert info.value.argument == argument and says in str(info.value), str(info.value)


@pytest.mark.parametrize(("kw", "says"), [
    ({"period": float("nan")}, "period = nan must be a finite number > 0 (s)"),  # before: NaN motion
    ({"period": float("inf")}, "period = inf must be a finite number > 0 (s)"),  # before: NaN motion
    ({"period": 0.0}, "period = 0.0 must be a finite number > 0 (s)"),  # before: ZeroDivisionError
    ({"amplitude": float("nan")}, "amplitude = nan must be a finite number > 0"),  # before: NaN motion
    ({"harmonics": 0}, "harmonics = 0 must be an integer from 1 to 50"),  # before: slice step cannot be zero
])
def test_excitation_arguments_are_refused_by_name(kw, says):
    from planardyn import identify

    mech = pd.load_example("five-bar")
    with pytest.raises(pd.ArgumentError) as info:
        identify.excitation(mech, base=identify.base_parameters(mech, samples=20), max_evaluations=3, **kw)
    assert info.value.argument == next(iter(kw)) and str(info.value).startswith(says), str(info.value)
