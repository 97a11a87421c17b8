"""planardyn.robot.modes (assembly and working modes) and planardyn.robot.capability
(guaranteed end-effector acceleration at rest under effort limits)."""

from __future__ import annotations

import numpy as np
import planardyn as pd
import pytest
from conftest import MODELS
from planardyn import robot
from planardyn.robot.capability import max_acceleration

# Positions: the core solves to ~1e-12 L; the requirement is 1e-9 m.
POS_TOL = 1e-9
# The brute-force check of the capability value: A qdd = b solved in double precision.
ACC_RTOL = 1e-8


@pytest.fixture(scope="module")
def ee():
    return robot.EndEffector(pd.load(MODELS / "five-bar.yaml"), "P")


def test_five_bar_has_two_assembly_modes_with_the_drawn_one(ee):
    mech = ee.mech
    modes = robot.assembly_modes(mech, mech.drawn_q, starts=16)
    assert len(modes) == 2
    assert sorted(m.name for m in modes) == ["+", "-"]
    drawn = mech.point_positions(mech.x0)
    assert any(np.abs(m.points - drawn).max() < POS_TOL for m in modes)
    assert modes[0].name == "+" and np.abs(modes[0].points - drawn).max() < POS_TOL  # elbow up
    down = modes[1]
    assert down.points[mech.point_names.index("P")][1] < 0.1  # elbow down, below the base line
    redrawn = down.mechanism()  # picks that mode: assembles and simulates on it
    assert np.abs(redrawn.point_positions(redrawn.assemble(down.q)) - down.points).max() < POS_TOL
    res = redrawn.simulate(0.05, output_dt=0.05)
    assert res.success


def test_five_bar_has_four_working_modes_reproducing_the_target(ee):
    X = ee.home() + np.array([0.02, 0.03])
    modes = robot.working_modes(ee, X)
    assert len(modes) == 4
    assert len({m.name for m in modes}) == 4
    iP = ee.mech.point_names.index("P")
    for mode in modes:
        m = mode.mechanism()
        assert np.abs(m.point_positions(m.assemble(mode.q))[iP] - X).max() < POS_TOL
        assert mode.sigma_min > 0
    # The drawn working mode is among them.
    q_drawn = ee.inverse(X).q
    assert min(np.abs(m.q - q_drawn).max() for m in modes) < 1e-8


def test_general_multistart_finds_the_same_working_modes(ee, monkeypatch):
    from planardyn.robot import modes as M

    X = ee.home() + np.array([0.02, 0.03])
    closed = M.working_modes(ee, X)
    monkeypatch.setattr(M, "_five_bar_legs", lambda ee: None)
    found = M.working_modes(ee, X, starts=48)
    assert 1 <= len(found) <= 4
    for mode in found:
        assert min(np.abs(c.points - mode.points).max() for c in closed) < 1e-8


def test_capability_value_matches_forward_dynamics(ee):
    mech = ee.mech
    tau_max = np.array([12.0, 12.0])
    cmap = robot.capability_map(ee, (-0.15, 0.15), (0.35, 0.6), 7, tau_max)
    j, i = 3, 3
    q = cmap.grid.q[j, i]
    r, t = cmap.accel[j, i], cmap.direction[j, i]
    assert r > 0
    d = np.array([np.cos(t), np.sin(t)])
    J = ee.state(q).J
    A = mech.mass_matrix(q)
    g = mech.inverse_dynamics(q, np.zeros(2), np.zeros(2))
    tau = A @ np.linalg.solve(J, r * d) + g
    assert np.abs(tau).max() == pytest.approx(tau_max.max(), rel=1e-12)  # on a limit
    qdd = mech.forward_dynamics(q, np.zeros(2), tau=tau)
    a = J @ qdd  # + convective term, 0 at rest
    assert np.linalg.norm(a - r * d) <= ACC_RTOL * r
    # No direction does better than r: a bit more along d breaks a limit.
    M = A @ np.linalg.inv(J)
    assert np.any(np.abs(M @ (1.001 * r * d) + g) > tau_max)
    assert max_acceleration(M, g, tau_max, d) == pytest.approx(r, rel=1e-12)


def test_capability_is_zero_where_holding_exceeds_the_limits(ee):
    tau_max = np.array([6.0, 6.0])
    cmap = robot.capability_map(ee, (-0.3, 0.3), (0.1, 0.6), 9, tau_max)
    reach = np.isfinite(cmap.accel)
    over = reach & np.any(np.abs(cmap.holding) > tau_max, axis=-1)
    assert over.any() and (reach & ~over).any()
    assert np.all(cmap.accel[over] == 0)
    assert np.all(cmap.accel[reach & ~over] > 0)


def test_plots_draw(ee):
    from matplotlib.figure import Figure

    modes = robot.working_modes(ee, ee.home())
    assert robot.plot_modes(modes, Figure().subplots())
    cmap = robot.capability_map(ee, (-0.1, 0.1), (0.4, 0.5), 4, 20.0)
    assert robot.plot_capability(cmap, Figure().subplots())
