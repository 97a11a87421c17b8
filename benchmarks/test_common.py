"""The benchmark's shared helpers agree with planardyn, which reads the same model files
independently: masses, inertias and centres of mass, the spanning tree, the energy (balance)
and the loop gap. Run with ``.venv/bin/python -m pytest -q benchmarks``; the Pinocchio check
runs where Pinocchio is installed (``benchmarks/.venv-peers``, with ``PYTHONPATH=python``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import common  # noqa: E402
import mechanisms  # noqa: E402
from peers import planardyn_peer as P  # noqa: E402

pd = pytest.importorskip("planardyn")
BENCHES = pytest.mark.parametrize("bm", mechanisms.ALL, ids=lambda b: b.key)


@BENCHES
def test_bodies_as_planardyn_reads_them(bm):
    d, mech = common.load_drawing(bm.spec), P.mechanism(bm)
    assert list(d.bodies) == mech.body_names
    np.testing.assert_allclose([b.mass for b in d.bodies.values()], mech.masses, rtol=1e-14)
    np.testing.assert_allclose([b.inertia for b in d.bodies.values()], mech.inertias, rtol=1e-12)
    com = np.array([b.com for b in d.bodies.values()])
    np.testing.assert_allclose(com, mech.x0.reshape(-1, 3)[:, :2], atol=1e-14)


@BENCHES
def test_tree_spans_the_bodies_depth_first(bm):
    d = common.load_drawing(bm.spec)
    tree, closing = d.tree()
    assert sorted(p.b for p in tree) == sorted(d.bodies)  # one joint per body
    # Mobility: 3 per body, 2 per pair = the number of coordinates.
    assert 3 * len(d.bodies) - 2 * (len(tree) + len(closing)) == len(d.coordinates)
    # Depth-first: each body's subtree follows it without a gap (Pinocchio relies on it).
    order = [p.b for p in tree]
    for i, p in enumerate(tree):
        sub = {p.b}
        for q in tree[i + 1:]:
            if q.a not in sub:
                break
            sub.add(q.b)
        assert all(order.index(q.b) < i + len(sub) for q in tree if q.a in sub)
    assert {c.pair.name for c in d.coordinates} <= {p.name for p in tree}


@BENCHES
def test_energy_and_gap_on_a_planardyn_trajectory(bm):
    """At the drawing, E = planardyn's T + V; along a tight run the balance (with the drives'
    work) stays constant, and the loop gap is round-off; a moved body opens it by as much."""
    d, mech = common.load_drawing(bm.spec), P.mechanism(bm)
    res = mech.simulate(bm.t_end / 4, method="dop853", rtol=1e-11, atol=1e-11)
    poses, rates = P.split(mech, res.x, res.xd)
    e = common.energy(d, poses, rates)
    scale = max(1.0, float(np.max(np.abs(res.energy.total))))
    assert e[0] == pytest.approx(sum(mech.energy(mech.q0, mech.qd0)), abs=1e-12 * scale)
    # T + V - E is the drives' work at every output, whatever the integration error.
    np.testing.assert_allclose(res.energy.total - e, res.energy.work - res.energy.work[0], atol=1e-12 * scale)
    assert np.max(np.abs(e - e[0])) < 1e-8 * scale
    assert np.max(common.loop_gap(d, poses)) < 1e-12
    np.testing.assert_allclose(common.coordinates(d, poses), res.q, atol=1e-12)
    body = next(iter(d.bodies))
    poses[body] = poses[body] + np.array([3e-4, 0.0, 0.0])
    assert np.max(common.loop_gap(d, poses)) == pytest.approx(3e-4, rel=1e-9)


@BENCHES
def test_mujoco_model_accelerates_as_planardyn(bm):
    """At rest in the drawing MuJoCo's acceleration is the constrained one, up to the soft
    constraint's regularisation (solimp d = 0.9999: about 1e-4 relative)."""
    mujoco = pytest.importorskip("mujoco")
    from peers import mujoco_peer as M

    d, mech = common.load_drawing(bm.spec), P.mechanism(bm)
    model = mujoco.MjModel.from_xml_string(M.mjcf(d, "RK4", 1e-4, True))
    data = mujoco.MjData(model)
    data.ctrl[:] = [c.effort for c in d.coordinates if c.effort]
    mujoco.mj_forward(model, data)
    idx = [model.jnt_dofadr[model.joint(c.pair.name).id] for c in d.coordinates]
    expected = mech.forward_dynamics(mech.q0, np.zeros(mech.dof), t=0.0)
    np.testing.assert_allclose(data.qacc[idx], expected, rtol=1e-3, atol=1e-3 * np.max(np.abs(expected)))


@BENCHES
def test_pinocchio_model_accelerates_as_planardyn(bm):
    pytest.importorskip("pinocchio")
    from peers import pinocchio_peer as Q

    d, mech = common.load_drawing(bm.spec), P.mechanism(bm)
    m = Q.Model(d, 0.0)
    q0 = np.zeros(m.model.nq)
    a = m.pin.constraintDynamics(m.model, m.data, q0, np.zeros(m.model.nv), m.spring_tau(q0) if m.springs else m.tau,
                                 m.cmodels, m.cdatas, m.prox)
    idx = [m.model.joints[m.jid[c.pair.b]].idx_v for c in d.coordinates]
    expected = mech.forward_dynamics(mech.q0, np.zeros(mech.dof), t=0.0)
    np.testing.assert_allclose(a[idx], expected, rtol=1e-9, atol=1e-9 * np.max(np.abs(expected)))


@BENCHES
def test_pinocchio_body_states_are_its_kinematics(bm):
    """The peer's vectorised body states equal Pinocchio's own forward kinematics at arbitrary
    states (round-off: 1e-12 on positions of order 1 m and rates of order 10 m/s)."""
    pin = pytest.importorskip("pinocchio")
    from peers import pinocchio_peer as Q

    d = common.load_drawing(bm.spec)
    m = Q.Model(d, 0.0)
    rng = np.random.default_rng(7)
    qs, vs = rng.uniform(-3, 3, (5, m.model.nq)), rng.uniform(-10, 10, (5, m.model.nv))
    poses, rates = m.body_states(qs, vs)
    for i in range(len(qs)):
        pin.forwardKinematics(m.model, m.data, qs[i], vs[i])
        for name, b in d.bodies.items():
            M, vel = m.data.oMi[m.jid[name]], m.data.v[m.jid[name]]  # vel: joint frame, local axes
            c = Q.v3(b.com - m.origin[name])
            np.testing.assert_allclose(poses[name][i, :2], (M.translation + M.rotation @ c)[:2], atol=1e-12)
            angle = np.arctan2(M.rotation[1, 0], M.rotation[0, 0])
            assert np.cos(poses[name][i, 2] - angle) == pytest.approx(1.0, abs=1e-12)
            np.testing.assert_allclose(rates[name][i, :2], (M.rotation @ (vel.linear + np.cross(vel.angular, c)))[:2],
                                       atol=1e-12)
            assert rates[name][i, 2] == pytest.approx(vel.angular[2], abs=1e-12)
