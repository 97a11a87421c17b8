"""Motors with transmissions, friction from the pair loads, and the sizing report's limit
checks (docs/actuators.md), through the Python API."""

from __future__ import annotations

import copy
import json

import numpy as np
import planardyn as pd
import pytest
from conftest import MODELS, cli_run
from planardyn import robot, structure
from scipy.integrate import solve_ivp

G = 9.81
PENDULUM = """
name: pendulum with pin friction
gravity: [0, -9.81]
points: {O: [0, 0], A: [0.8, 0]}
ground: [O]
bodies:
  bar: {points: [O, A], uniform_bar: [O, A], mass: 2.0}
pairs:
  - {type: revolute, name: O, at: O, bodies: [ground, bar]}
coordinates:
  - {name: theta, pair: O, value: 0.0}
loads:
  - {type: friction, pair: O, mu: 0.3, pin_radius: 0.02, stiction_speed: 1.0e-3}
"""


def pendulum_rhs(_t: float, y: np.ndarray) -> list[float]:
    """theta'' of the bar (m = 2 kg, L = 0.8 m, I_O = m L^2 / 3) with pin friction
    mu r |F| tanh(r theta' / v_st), F = m a_c - m g solved with theta'' by fixed point."""
    theta, w = y
    m, lc, i_o, mu, r, v_st = 2.0, 0.4, 2.0 * 0.64 / 3.0, 0.3, 0.02, 1e-3
    s, c = np.sin(theta), np.cos(theta)
    qdd = 0.0
    for _ in range(200):
        f = np.hypot(m * lc * (-s * qdd - c * w * w), m * lc * (c * qdd - s * w * w) + m * G)
        new = (-m * G * lc * c - mu * r * f * np.tanh(r * w / v_st)) / i_o
        if abs(new - qdd) <= 1e-15 * max(abs(new), 1.0):
            break
        qdd = new
    return [w, new]


def test_pendulum_with_pin_friction_against_scipy():
    mech = pd.loads(PENDULUM)
    res = mech.simulate(2.0, method="dop853", rtol=1e-11, atol=1e-13, t_eval=[1.0, 2.0])
    ref = solve_ivp(pendulum_rhs, (0.0, 2.0), [0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-13, t_eval=[1.0, 2.0])
    # Both integrate to ~1e-11 relative: they agree to 1e-8 rad and 1e-7 rad/s.
    np.testing.assert_allclose(res.q[:, 0], ref.y[0], atol=1e-8)
    np.testing.assert_allclose(res.qd[:, 0], ref.y[1], atol=1e-7)


def slider_crank(friction: bool) -> pd.Mechanism:
    model = pd.load(MODELS / "slider-crank.yaml").to_dict()
    model["loads"] = [ld for ld in model.get("loads", []) if ld["type"] != "friction"]
    if friction:
        names = [p.get("name") for p in model["pairs"]]
        for k, p in enumerate(model["pairs"]):
            if p.get("name") is None:
                p["name"] = f"pin{k}"
                names[k] = p["name"]
            if p["type"] == "revolute":
                model["loads"].append({"type": "friction", "pair": p["name"], "mu": 0.15, "pin_radius": 0.01})
            else:
                model["loads"].append({"type": "friction", "pair": p["name"], "mu": 0.2, "length": 0.04})
    return pd.from_dict(model)


def test_drive_power_is_frictionless_power_plus_dissipated_power():
    with_f, without = slider_crank(True), slider_crank(False)
    t = np.linspace(0.0, 1.0, 201)
    q0 = with_f.q0[0]
    q = (q0 + 6.0 * t + 0.8 * np.sin(3 * t))[:, None]
    qd = (6.0 + 2.4 * np.cos(3 * t))[:, None]
    qdd = (-7.2 * np.sin(3 * t))[:, None]
    tau, tau0 = with_f.inverse_dynamics(q, qd, qdd), without.inverse_dynamics(q, qd, qdd)
    lost = with_f.dissipated_power(q, qd, qdd)
    assert lost.shape == (201,) and np.all(lost > 0)
    # The balance holds at every row to round-off (virtual power, the same motion).
    np.testing.assert_allclose(tau[:, 0] * qd[:, 0], tau0[:, 0] * qd[:, 0] + lost, rtol=1e-10, atol=1e-10)


GEARED = {"gear_ratio": 40.0, "efficiency": 0.85, "rotor_inertia": 2e-5, "viscous": 1e-5, "coulomb": 0.005}


def five_bar_with_motors(limits: dict[str, dict[str, float]] | None = None) -> pd.Mechanism:
    model = copy.deepcopy(pd.load(MODELS / "five-bar.yaml").to_dict())
    model["actuators"] = [{"coordinate": c, **GEARED, **({"limits": limits[c]} if limits else {})}
                          for c in ("theta1", "theta2")]
    return pd.from_dict(model)


def sized(mech: pd.Mechanism) -> robot.SizingReport:
    ee = robot.EndEffector(mech, "P")
    home = ee.home()
    return robot.size(ee, robot.circle(home[:2] + [0.0, 0.03], 0.03, 0.5), dt=2e-3)


def test_motor_side_of_the_sizing_report():
    rep = sized(five_bar_with_motors())
    n, eta, j = GEARED["gear_ratio"], GEARED["efficiency"], GEARED["rotor_inertia"]
    m = rep.motion
    fine = robot.solve_motion(m.effector, robot.circle(m.X[0] + [0.0, 0.03], 0.03, 0.5), dt=2e-5)
    for k, d in enumerate(rep.drives):
        mo = d.motor
        assert mo is not None and mo.checks == []
        # Motor speed n qd; motor torque J n qdd (the rotor, on the ground, before the gear)
        # + friction + tau / (n eta) while motoring, tau eta / n while back-driven (the
        # transmission's definition, docs/actuators.md).
        w = n * m.qd[:, k]
        fr = GEARED["viscous"] * w + GEARED["coulomb"] * np.tanh(w / 1e-2)
        gear = np.where(m.tau[:, k] * m.qd[:, k] >= 0, m.tau[:, k] / (n * eta), m.tau[:, k] * eta / n)
        np.testing.assert_allclose(mo.torque, j * n * m.qdd[:, k] + gear + fr, rtol=1e-12, atol=1e-15)
        # The peak between the samples (the sizing resamples around it): the motion's, 100
        # times finer, to 1e-6.
        assert mo.peak_speed == pytest.approx(n * np.abs(fine.qd[:, k]).max(), rel=1e-6)
    # The rotors are their motors': the joint-side efforts are the bare five-bar's.
    bare = pd.load(MODELS / "five-bar.yaml")
    np.testing.assert_allclose(m.tau, bare.inverse_dynamics(m.q, m.qd, m.qdd), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("quantity", ["peak torque", "RMS torque", "speed", "torque-speed"])
def test_limit_checks_pass_just_inside_and_fail_just_outside(quantity):
    need = sized(five_bar_with_motors()).drives
    for factor, expected in ((1.0 + 1e-6, True), (1.0 - 1e-6, False)):
        limits = {}
        for d in need:
            mo = d.motor
            assert mo is not None
            if quantity == "peak torque":
                lim = {"peak_torque": mo.peak_torque * factor}
            elif quantity == "RMS torque":
                lim = {"continuous_torque": mo.rms_torque * factor}
            elif quantity == "speed":
                lim = {"max_speed": mo.peak_speed * factor}
            else:
                # A flat envelope at the peak torque up to 10x the speed: the ratio is the peak's.
                top = 10 * mo.peak_speed
                lim = {"torque_speed": [[0.0, mo.peak_torque * factor], [top, mo.peak_torque * factor]]}
            limits[d.name] = lim
        rep = sized(five_bar_with_motors(limits))
        for d in rep.drives:
            assert d.motor is not None
            (check,) = d.motor.checks
            assert check.quantity == quantity
            assert check.passed is expected and d.motor.passed is expected
            assert check.margin == pytest.approx(1.0 - 1.0 / factor, rel=1e-6)
        text = str(rep)
        assert ("FAIL" in text) is not expected


def test_motor_envelope_with_a_corner():
    mech = five_bar_with_motors({c: {"peak_torque": 1.0, "max_speed": 300.0, "corner_speed": 200.0}
                                 for c in ("theta1", "theta2")})
    # Peak torque up to the corner, then linear to 0 at the maximum speed.
    np.testing.assert_allclose(mech.available_torque(0, [0.0, 150.0, -200.0, 250.0, 300.0, 400.0]),
                               [1.0, 1.0, 1.0, 0.5, 0.0, 0.0], atol=1e-15)


def test_bad_actuators_are_refused_with_their_field():
    model = pd.load(MODELS / "five-bar.yaml").to_dict()
    for bad, path in (({"coordinate": "theta1", "efficiency": 1.2}, "actuators[0].efficiency"),
                      ({"coordinate": "nope"}, "actuators[0].coordinate"),
                      ({"coordinate": "theta1", "limits": {"corner_speed": 3.0}}, "actuators[0].limits")):
        with pytest.raises(pd.ModelError) as info:
            pd.from_dict({**model, "actuators": [bad]})
        assert info.value.path == path
    with pytest.raises(pd.ModelError) as info:
        pd.from_dict({**model, "loads": [{"type": "friction", "pair": "elbow1", "mu": 0.1}]})
    assert info.value.path == "loads[0].pin_radius"


def three_legged(actuated: tuple[str, ...] = ("motor3",)) -> pd.Mechanism:
    """The five-bar with a third leg A3 -> C3 -> P (0.25 m, 0.35 m); ``actuated``: the pairs
    with an actuator besides the coordinates' (A3's)."""
    model = pd.load(MODELS / "five-bar.yaml").to_dict()
    model["loads"], model["drives"] = [], []
    model["points"] |= {"A3": [0.0, 0.0], "C3": [0.1983444079681374, 0.1521824425739351]}
    model["ground"].append("A3")
    model["bodies"] |= {"proximal_mid": {"points": ["A3", "C3"], "uniform_bar": ["A3", "C3"], "mass": 0.5},
                        "distal_mid": {"points": ["C3", "P"], "uniform_bar": ["C3", "P"], "mass": 0.7}}
    model["pairs"] += [{"type": "revolute", "name": "motor3", "at": "A3", "bodies": ["ground", "proximal_mid"]},
                       {"type": "revolute", "name": "elbow3", "at": "C3", "bodies": ["proximal_mid", "distal_mid"]},
                       {"type": "revolute", "name": "effector3", "at": "P", "bodies": ["distal_left", "distal_mid"]}]
    model["actuators"] = [{"pair": p} for p in actuated]
    return pd.from_dict(model)


def test_redundant_efforts_min_norm_and_forward():
    mech = three_legged()
    assert mech.actuator_names == ["theta1", "theta2", "motor3"]
    assert structure.analyse(mech).actuation == 3
    q, qd, qdd = mech.q0 + [0.05, -0.04], [1.2, -0.7], [3.0, 5.0]
    out = mech.distribute_efforts(q, qd, qdd)
    # Minimum norm: numpy's least-squares solution of B tau = the generalized efforts.
    tau_gen = out["B"] @ out["efforts"]
    np.testing.assert_allclose(out["efforts"], np.linalg.lstsq(out["B"], tau_gen, rcond=None)[0], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(out["B"] @ out["internal"].T, 0.0, atol=1e-13)
    for how in ({"method": "min_max"}, {"method": "preload", "preload": [3.0]}):
        e = mech.distribute_efforts(q, qd, qdd, **how)["efforts"]
        np.testing.assert_allclose(mech.forward_dynamics_actuated(q, qd, e), qdd, rtol=1e-10)
    with pytest.raises(ValueError):
        mech.distribute_efforts(q, qd, qdd, method="preload")


def test_min_max_with_three_internal_forces_against_linprog():
    """5 actuators on 2 degrees of freedom (motor3 and two elbows besides the coordinates):
    the least largest effort against scipy's HiGHS on the LP over the efforts themselves,
    min s subject to B tau = B tau_min_norm, -s <= tau_a <= s."""
    from scipy.optimize import linprog

    mech = three_legged(("motor3", "elbow1", "elbow3"))
    q, qd, qdd = mech.q0 + [0.05, -0.04], [1.2, -0.7], [3.0, 5.0]
    out = mech.distribute_efforts(q, qd, qdd, method="min_max")
    assert out["internal"].shape == (3, 5)
    b, tau = out["B"], out["B"] @ mech.distribute_efforts(q, qd, qdd)["efforts"]
    eye, ones = np.eye(5), np.ones((5, 1))
    ref = linprog(c=[0.0] * 5 + [1.0], A_ub=np.block([[eye, -ones], [-eye, -ones]]), b_ub=np.zeros(10),
                  A_eq=np.hstack([b, np.zeros((2, 1))]), b_eq=tau, bounds=[(None, None)] * 6, method="highs")
    assert ref.status == 0
    largest = np.abs(out["efforts"]).max()
    # HiGHS's optimality tolerance (1e-7 relative) bounds the agreement.
    assert largest == pytest.approx(ref.fun, rel=1e-7)
    assert largest < np.abs(mech.distribute_efforts(q, qd, qdd)["efforts"]).max()
    np.testing.assert_allclose(b @ out["efforts"], tau, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(mech.forward_dynamics_actuated(q, qd, out["efforts"]), qdd, rtol=1e-10)


def three_legged_geared_pair() -> pd.Mechanism:
    """The three-legged five-bar whose motor3 actuator is a geared motor (n = 15, eta = 0.85,
    J = 3e-5 kg m^2, no motor friction, peak torque 2 N m); the coordinates' drives ideal."""
    model = three_legged().to_dict()
    model["actuators"] = [{"pair": "motor3", "gear_ratio": 15.0, "efficiency": 0.85, "rotor_inertia": 3e-5,
                           "limits": {"peak_torque": 2.0}}]
    return pd.from_dict(model)


def test_a_geared_pair_actuator_motor_torque_reproduces_the_motion():
    mech, ideal = three_legged_geared_pair(), three_legged()
    assert [a is None for a in mech.actuators] == [True, True, False]
    assert mech.actuators[2]["gear_ratio"] == 15.0
    q, qd, qdd = mech.q0 + [0.05, -0.04], [1.2, -0.7], [3.0, 5.0]
    out = mech.distribute_efforts(q, qd, qdd)
    rates = out["B"].T @ qd
    t_m = mech.motor_torques(q, qd, qdd, out["efforts"])
    np.testing.assert_array_equal(t_m, out["motor_torques"])
    np.testing.assert_array_equal(t_m[:2], out["efforts"][:2])  # the ideal drives' torques are their efforts
    np.testing.assert_allclose(mech.forward_dynamics_actuated(q, qd, t_m), qdd, rtol=1e-10)
    # The rotor turns before its gear: the shares are the ideal model's, and motor3's torque is
    # its gear's input, tau / (n eta) motoring or tau eta / n back-driven (no motor friction),
    # plus the rotor's own J n qdd_3 (qdd_3 the pair's acceleration), which forward dynamics
    # above takes back.
    e0 = ideal.distribute_efforts(q, qd, qdd)["efforts"]
    np.testing.assert_allclose(out["efforts"], e0, rtol=1e-12, atol=1e-12)
    e3, p3 = out["efforts"][2], out["efforts"][2] * rates[2]
    rotor = t_m[2] - (e3 / (15.0 * 0.85) if p3 >= 0 else e3 * 0.85 / 15.0)
    assert abs(rotor) > 1e-3 * abs(t_m[2])


def test_sizing_sizes_a_geared_pair_actuators_motor():
    mech = three_legged_geared_pair()
    ee = robot.EndEffector(mech, "P")
    home = ee.home()
    rep = robot.size(ee, robot.circle(home[:2] + [0.0, 0.02], 0.02, 0.5), dt=5e-3)
    drive = rep.drives[2]
    assert [d.motor is None for d in rep.drives] == [True, True, False]
    # The peaks between the samples (the sizing resamples around them): the motion's, 100
    # times finer, to 1e-6.
    m = robot.solve_motion(ee, robot.circle(home[:2] + [0.0, 0.02], 0.02, 0.5), dt=5e-5)
    efforts, rates, torques = robot.sizing.distributed_efforts(mech, m)
    t_m = torques[:, 2]
    np.testing.assert_allclose(t_m, mech.motor_torques(m.q, m.qd, m.qdd, efforts)[:, 2], rtol=1e-12, atol=1e-15)
    assert drive.motor.peak_torque == pytest.approx(np.abs(t_m).max(), rel=1e-6)
    assert drive.motor.peak_speed == pytest.approx(15.0 * np.abs(rates[:, 2]).max(), rel=1e-6)
    assert [c.quantity for c in drive.motor.checks] == ["peak torque"]
    assert drive.motor.checks[0].limit == 2.0


def test_sizing_a_redundantly_actuated_robot_sizes_every_actuator(tmp_path):
    mech = three_legged()
    ee = robot.EndEffector(mech, "P")
    home = ee.home()
    path = robot.circle(home[:2] + [0.0, 0.02], 0.02, 0.5)
    rep = robot.size(ee, path, dt=5e-3)
    assert [d.name for d in rep.drives] == ["theta1", "theta2", "motor3"]
    m = rep.motion
    peaks = np.array([d.peak_effort for d in rep.drives])
    # The shares reproduce the generalized efforts of the motion: B tau_a = tau at every row.
    row = len(m.t) // 2
    out = mech.distribute_efforts(m.q[row], m.qd[row], m.qdd[row])
    np.testing.assert_allclose(out["B"] @ out["efforts"], m.tau[row], rtol=1e-10, atol=1e-10)
    # Min-max makes every row's largest effort least, so its peak over the motion is at most
    # min-norm's.
    mm = robot.size(ee, path, dt=5e-3, distribution="min_max")
    assert max(d.peak_effort for d in mm.drives) <= peaks.max() * (1 + 1e-12)
    # From the shell, with a preload.
    model = tmp_path / "three.json"
    model.write_text(json.dumps(mech.to_dict()))
    c = home[:2] + [0.0, 0.02]
    assert robot.size_cli([str(model), "--circle", str(c[0]), str(c[1]), "0.02", "--duration", "0.5", "--dt", "5e-3",
                           "--distribution", "preload", "--preload", "2.0"]) == 0


def test_gear_mesh_friction_costs_its_dissipated_power_and_keeps_the_energy_balance() -> None:
    # The shipped gear train with Coulomb friction at its three meshes (mu = 0.06, pressure
    # angle 20 degrees): along a speeding-up and slowing-down motion the drive power exceeds
    # the frictionless one by the dissipated power (virtual power, to round-off), and a run
    # keeps T + V - W constant with W counting the meshes' loss (docs/actuators.md).
    text = (MODELS / "gear-train.yaml").read_text()
    meshes = "".join(f"  - {{type: friction, pair: {m}, mu: 0.06}}\n" for m in ("mesh1", "mesh2", "rack_mesh"))
    with_friction = pd.loads(text.replace("simulate:", f"loads:\n{meshes}\nsimulate:"))
    frictionless = pd.load(MODELS / "gear-train.yaml")
    t = np.linspace(0.0, 1.0, 101)
    q, qd, qdd = (10 * t + np.sin(6 * t))[:, None], (10 + 6 * np.cos(6 * t))[:, None], (-36 * np.sin(6 * t))[:, None]
    power = with_friction.inverse_dynamics(q, qd, qdd)[:, 0] * qd[:, 0]
    power0 = frictionless.inverse_dynamics(q, qd, qdd)[:, 0] * qd[:, 0]
    lost = with_friction.dissipated_power(q, qd, qdd)
    # At t = 0 qdd = 0 and nothing loads the teeth (no gravity, no load): no loss there.
    assert lost[0] == 0.0 and np.all(lost[1:] > 0.0)
    np.testing.assert_allclose(power - power0, lost, rtol=1e-10, atol=1e-13)
    run = with_friction.simulate()
    assert np.max(np.abs(run.energy.balance - run.energy.balance[0])) <= 1e-9
    # The meshes took energy: the train ends slower than without them (0.1625 J frictionless).
    assert run.energy.kinetic[-1] < 0.95 * frictionless.simulate().energy.kinetic[-1]


def with_pin_friction(name: str, pair: str, mu: float) -> pd.Mechanism:
    """A shipped model with Coulomb friction mu at `pair`: the slider-crank's crank pin
    (radius 8 mm) or the Scotch yoke's slot pin."""
    model = pd.load_example(name).to_dict()
    load = {"type": "friction", "pair": pair, "mu": mu} | ({"pin_radius": 0.008} if pair == "crank_pin" else {})
    model["loads"] = model.get("loads", []) + [load]
    return pd.from_dict(model)


@pytest.mark.parametrize(("name", "pair"), [("slider-crank", "crank_pin"), ("scotch-yoke", "pin")])
def test_self_locking_friction_is_refused_at_any_mu(name, pair, tmp_path):
    # Issue 23, finding 4: from mu ~ 1e4 (slider-crank) and 3e3 (Scotch yoke) the fixed point
    # overflowed and forward_dynamics returned -1.1e297, a run kept a row of it. Both
    # self-lock at their start states for every mu here: forward dynamics, simulate, a batch
    # and the CLI must say so and never give a number.
    for mu in (1e2, 1e3, 1e4, 1e6, 1e10, 1e15, 1e20):
        mech = with_pin_friction(name, pair, mu)
        with pytest.raises(pd.PlanardynError, match="self-locks") as e:
            mech.forward_dynamics(mech.q0, mech.qd0)
        assert e.value.iterations <= 100 and np.isfinite(e.value.change)
        with pytest.raises(pd.PlanardynError, match="self-locks"):
            mech.simulate(0.2)
        (out,) = pd.batch.simulate([(mech, {})], t_end=0.2)
        assert isinstance(out, pd.batch.BatchError) and "self-locks" in out.message
    # Once, from the shell: an error naming the cause, no results file.
    model = tmp_path / "locked.json"
    model.write_text(json.dumps(with_pin_friction(name, pair, 1e15).to_dict()))
    code, err = cli_run("simulate", model, "--t-end", "0.2", "-o", tmp_path / "out.csv")
    assert code != 0 and "self-locks" in err and not (tmp_path / "out.csv").exists()


def test_a_run_that_self_locks_on_the_way_stops_with_finite_rows(tmp_path):
    # mu = 6 on the slider-crank's crank pin settles at the start and locks at t = 0.40 s, as
    # the crank nears its dead centre: the run stops there with the reason, every row kept
    # finite (its largest |qdd| 1.24e3 rad/s^2), and so does its results file.
    mech = with_pin_friction("slider-crank", "crank_pin", 6.0)
    res = mech.simulate(1.0)
    assert not res.success and "self-locks" in res.message and 0.3 < res.t[-1] < 0.5
    assert np.isfinite(res.qdd).all() and np.abs(res.qdd).max() < 1e4
    back = pd.read_results(res.save(tmp_path / "run.csv"))
    assert np.isfinite(back.qdd).all() and np.isfinite(back.tau).all()
