"""The motor-torque and losses queries on rows around the five-bar-robot's cranks' stalls
(qd_k = 0, where its gears change branch and its pins' friction changes direction): what the
methods' docstrings promise holds there too (a dense re-check of them)."""

from __future__ import annotations

import copy

import numpy as np
import planardyn as pdy
import yaml
from conftest import MODELS

# The round trip's bound, test_results_motor's: forward dynamics of the motor torques gives qdd
# back to round-off of the friction's fixed point (settled to 1e-13 relative); measured 6.4e-15.
ROUND_TRIP = 1e-9
# The power identity's: (tau - tau_0) . qd and the dissipated power are sums of a few products of
# the same efforts; measured 2.2e-16 of max |tau qd|.
POWER = 1e-13


def test_motor_torques_and_losses_hold_around_stalls():
    # Each crank q_k = q0_k + a_k sin(w_k t): a stall at w_k t = pi/2 + j pi; rows at it and
    # 1e-12 .. 1e-2 s either side, three stalls per crank (258 rows).
    model = yaml.safe_load((MODELS / "five-bar-robot.yaml").read_text())
    mech = pdy.from_dict(model)
    bare_model = copy.deepcopy(model)
    bare_model["loads"] = [ld for ld in model["loads"] if not (ld.get("type") == "friction" and ld.get("mu"))]
    assert len(bare_model["loads"]) == len(model["loads"]) - 3
    bare = pdy.from_dict(bare_model)
    a, w = np.array([0.3, 0.25]), np.array([5.0, 7.0])
    offsets = np.concatenate([-np.logspace(-2, -12, 21), [0.0], np.logspace(-12, -2, 21)])
    t = np.sort(np.concatenate([(np.pi / 2 + j * np.pi) / w[k] + offsets for k in range(2) for j in range(3)]))
    q = mech.q0 + a * np.sin(np.outer(t, w))
    qd = a * w * np.cos(np.outer(t, w))
    qdd = -a * w**2 * np.sin(np.outer(t, w))
    x = np.array([mech.kinematics(q[i], qd[i])["x"] for i in range(len(t))])
    tau = np.asarray(mech.inverse_dynamics(q, qd, qdd, x))
    t_m = np.asarray(mech.motor_torques(q, qd, qdd, tau, x=x))
    # Both gear branches occur (motoring tau qd > 0, back-driven < 0), and rows at rest.
    assert np.any(tau * qd > 0) and np.any(tau * qd < 0) and np.any(np.abs(qd) < 1e-12)
    # forward_dynamics' docstring: pass motor_torques(q, qd, qdd, tau) to get qdd back.
    for i in range(len(t)):
        back = mech.forward_dynamics(q[i], qd[i], tau=t_m[i], x_start=x[i])
        np.testing.assert_allclose(back, qdd[i], rtol=0, atol=ROUND_TRIP * max(np.abs(qdd[i]).max(), 1.0))
    # dissipated_power's: >= 0, and the drive power exceeds the frictionless one by exactly it.
    p = np.asarray(mech.dissipated_power(q, qd, qdd, x))
    assert (p >= 0).all() and p.max() > 0
    excess = np.sum((tau - np.asarray(bare.inverse_dynamics(q, qd, qdd, x))) * qd, axis=1)
    np.testing.assert_allclose(excess, p, rtol=0, atol=POWER * np.abs(tau * qd).max())
