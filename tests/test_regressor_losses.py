"""The regressor with the losses' columns along runs: motors behind transmissions, pin
friction, and a result's body rates near a type II singularity."""

from __future__ import annotations

import numpy as np
import planardyn as pd
import pytest


def geared_five_bar(efficiency: float = 0.9, pin_mu: float = 0.08):
    """The five-bar with geared motors on both cranks (ratio 10) and pin friction with a
    viscous part at its elbows, its drives scaled to the motors' side."""
    d = pd.load_example("five-bar").to_dict()
    d["actuators"] = [{"coordinate": c, "name": f"motor_{c}", "gear_ratio": 10.0, "efficiency": efficiency,
                       "rotor_inertia": 5e-5, "viscous": 2e-4, "coulomb": 0.02, "stiction_speed": 1.0}
                      for c in ("theta1", "theta2")]
    for drive in d["drives"]:
        law = drive.get("table", drive)
        law["effort"] = np.divide(law["effort"], 10.0).tolist()
    if pin_mu > 0:
        d["loads"] += [{"type": "friction", "pair": p, "mu": pin_mu, "pin_radius": 0.01, "viscous": 0.005,
                        "stiction_speed": 0.01}
                       for p in ("elbow1", "elbow2")]
    return pd.from_dict(d)



def drive_law_torques(mech, t):
    """The motor torques (N m) of the five-bar's drive laws at times t (N,): a constant and a table."""
    drives = mech.to_dict()["drives"]
    table = drives[1]["table"]
    return np.column_stack([np.full_like(t, drives[0]["effort"]), np.interp(t, table["t"], table["effort"])])

def test_parameters_follow_the_bodies_with_the_losses():
    mech = geared_five_bar()
    pars = mech.regressor_parameters
    assert list(pars)[: 4 * mech.n_bodies] == list(mech.inertial_parameters)
    assert list(pars)[4 * mech.n_bodies:] == [
        "J_motor_theta1", "fv_motor_theta1", "fc_motor_theta1", "J_motor_theta2", "fv_motor_theta2",
        "fc_motor_theta2", "fvp_elbow1", "fvp_elbow2", "mu_elbow1", "fcp_elbow1", "mu_elbow2", "fcp_elbow2"]
    assert [pars[k] for k in ("J_motor_theta1", "fv_motor_theta2", "fvp_elbow1", "mu_elbow2", "fcp_elbow2")] == [
        5e-5, 2e-4, 0.005, 0.08, 0.0]


def test_y_pi_plus_tau_o_is_the_simulated_motor_torque():
    # A run under the motors' torques (the five-bar's drive laws, a constant and a table, at
    # the motor side; efficiency 0.9, so both branches of the gears) with pin friction: the
    # regressor at the model's parameters gives back the motor torques the run applied,
    # from its positions, rates and accelerations. Exact in exact arithmetic; the pin
    # friction settles to 1e-13 of itself, round-off is 1e-14 of the efforts: 1e-10 of the
    # largest is the bound (measured 1.2e-13 of it).
    mech = geared_five_bar()
    # Started moving; where a gear comes to rest under a load it holds, it sticks (its motor
    # torque then any between its two branches': the regressor, like motor_torques, gives the
    # motoring one, tests/test_results_motor.py).
    res = mech.simulate(t_end=0.5, output_dt=0.005, qd0=[1.0, -0.8])
    assert res.success, res.message
    t_m = drive_law_torques(mech, res.t)
    Y, tau_o = mech.regressor(res.q, res.qd, res.qdd, x=res.x, xd=res.xd)
    assert Y.shape == (len(res.t), 2, 4 * mech.n_bodies + 12)
    pi = np.array(list(mech.regressor_parameters.values()))
    held = (np.abs(10.0 * res.qd) <= 1.0) & (np.abs(res.qdd + res.qd / 0.01) <= 1e-9 * np.abs(res.qdd).max())
    t_m[held] = res.tau_motor[held]
    np.testing.assert_allclose(Y @ pi + tau_o, t_m, rtol=0, atol=1e-10 * np.abs(t_m).max())
    # Both branches occur: motoring and generating rows.
    joint = mech.inverse_dynamics(res.q, res.qd, res.qdd, x=res.x, xd=res.xd)
    assert np.any(joint * res.qd > 0) and np.any(joint * res.qd < 0)


def test_regressor_takes_a_results_body_rates_near_a_type_ii_singularity():
    # The free-falling five-bar passes a type II singularity (sigma 8.6e-4 at its worst row):
    # with the run's xd the regressor's efforts are inverse dynamics' to round-off (measured
    # 3.0e-14 N m), and both are the passive run's 0 within the 1e-8 N m bound that
    # tests/test_dynamics.py keeps (measured 7.4e-11 N m). With the rates solved
    # from qd instead (x alone) one rounding unit of qd gives 2.5e-8 N m there.
    mech = pd.load_example("five-bar-free-fall")
    res = mech.simulate(t_end=1.0, method="dop853", rtol=1e-10, atol=1e-12)
    assert res.success and res.partitioned.any()
    pi = np.array(list(mech.regressor_parameters.values()))
    Y, tau_o = mech.regressor(res.q, res.qd, res.qdd, x=res.x, xd=res.xd)
    tau = mech.inverse_dynamics(res.q, res.qd, res.qdd, x=res.x, xd=res.xd)
    linear = Y @ pi + tau_o
    assert np.abs(linear - tau).max() < 1e-12
    assert np.abs(linear).max() < 1e-8
    # Rates of another state are refused, naming the row, as inverse dynamics does.
    xd = res.xd.copy()
    xd[7, 2] += 1e-6
    with pytest.raises(ValueError, match="row 7"):
        mech.regressor(res.q, res.qd, res.qdd, x=res.x, xd=xd)
