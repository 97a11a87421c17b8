"""Batch runs (planardyn.batch): native threads and a local Dask cluster of worker processes
both give, bit for bit, what a serial loop of Mechanism.simulate (or of the inverse dynamics)
gives; a failing variant is reported in its place without losing the others; sweep and
monte_carlo make the variants they say."""

from __future__ import annotations

import math
import os
import signal
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import planardyn as pd
import pytest
from conftest import MODELS
from planardyn import robot
from planardyn.batch import BatchError, BatchInterrupted, inverse_dynamics, monte_carlo, simulate, sweep

T_END = 0.1  # s: short runs, the test is about bookkeeping, not dynamics
# Proximal links straight out: C1 C2 = 0.8 m > 2 x 0.35 m, the distal links cannot meet.
IMPOSSIBLE_Q0 = [math.pi, 0.0]


@pytest.fixture(scope="module")
def five_bar():
    return pd.load(MODELS / "five-bar.yaml")


@pytest.fixture(scope="module")
def variants(five_bar):
    masses = sweep(five_bar, "bodies.distal_left.parts.1.mass", [0.1, 0.3, 0.6])
    starts = [(five_bar, {"q0": five_bar.q0 + [0.05 * k, -0.03 * k]}) for k in range(3)]
    return [*masses, *starts]


def serial(variants):
    out = []
    for v in variants:
        mech, own = v if isinstance(v, tuple) else (v, {})
        out.append(mech.simulate(T_END, **own))
    return out


def assert_same(a, b):
    assert isinstance(a, pd.SimulationResult), a
    for name in ("t", "q", "qd", "qdd", "tau", "x"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert (a.status, a.message) == (b.status, b.message)


def test_native_threads_equal_a_serial_loop(variants):
    expected = serial(variants)
    seen = []
    got = simulate(variants, T_END, threads=2, progress=lambda done, total: seen.append((done, total)))
    assert len(got) == len(expected)
    for a, b in zip(got, expected):
        assert_same(a, b)
        assert a.success
    assert seen[-1] == (len(variants), len(variants))
    # The variants differ: the sweep changed the motion.
    assert not np.array_equal(got[0].q, got[2].q)


def test_results_are_finished_in_the_native_threads(five_bar):
    """Each run's result is converted and finished by the worker that ran it, not by the
    calling thread (issue 25 item 4: that serial work capped two threads at about 1.6x);
    a failed variant's (type, message) pair reaches finish as it is."""
    from planardyn._core import simulate_batch

    caller = threading.get_ident()
    seen = []

    def finish(k, raw):
        seen.append((k, threading.get_ident(), type(raw).__name__))
        return k

    native = [(five_bar._native, {"q0": list(five_bar.q0 + [0.01 * k, 0.0]), "t_end": T_END}) for k in range(4)]
    native[2] = (five_bar._native, {"q0": IMPOSSIBLE_Q0, "t_end": T_END})
    assert simulate_batch(native, 2, finish) == [0, 1, 2, 3]
    assert sorted(k for k, _, _ in seen) == [0, 1, 2, 3]
    assert all(ident != caller for _, ident, _ in seen)
    assert {k: kind for k, _, kind in seen} == {0: "dict", 1: "dict", 2: "tuple", 3: "dict"}


def test_each_native_thread_keeps_one_python_state_for_the_whole_batch(five_bar):
    """A worker's Python thread state lives from its first variant to its last: a
    ``threading.local`` set while finishing one variant is there at the next on the same
    thread. Each variant made and freed a state of its own before (its frame stack mapped and
    unmapped each time), which took a batch of 1 s four-bar runs from 1.94x to 1.7x on two
    cores (docs/benchmarks.md, *Small and many runs*); a second batch starts afresh."""
    from planardyn._core import simulate_batch

    native = [(five_bar._native, {"q0": list(five_bar.q0 + [0.002 * k, 0.0]), "t_end": 0.01}) for k in range(40)]
    for _ in range(2):
        local = threading.local()
        counts: dict[int, int] = {}

        def finish(k, raw, local=local, counts=counts):
            local.n = getattr(local, "n", 0) + 1
            counts[threading.get_ident()] = local.n
            return k

        assert simulate_batch(native, 2, finish) == list(range(40))
        # Every variant finished on a thread whose state counted all its earlier ones.
        assert sum(counts.values()) == 40 and len(counts) <= 2


def test_a_failing_variant_is_reported_in_its_place(five_bar, variants):
    bad_model = five_bar.to_dict()
    bad_model["bodies"]["proximal_left"]["mass"] = -1.0
    mixed = [variants[0], (five_bar, {"q0": IMPOSSIBLE_Q0}), bad_model, (five_bar, {"method": "euler"}), variants[1]]
    got = simulate(mixed, T_END)
    assert isinstance(got[1], BatchError) and got[1].index == 1 and got[1].type == "AssemblyError"
    assert isinstance(got[2], BatchError) and got[2].type == "ModelError" and "mass" in got[2].message
    assert isinstance(got[3], BatchError) and got[3].type == "SimulationError" and not got[3].success
    # The same errors as the serial calls raise.
    with pytest.raises(pd.AssemblyError):
        five_bar.simulate(T_END, q0=IMPOSSIBLE_Q0)
    assert_same(got[0], serial(variants[:1])[0])
    assert_same(got[4], serial(variants[1:2])[0])


def test_any_concurrent_futures_executor(variants):
    with ThreadPoolExecutor(2) as ex:
        got = simulate(variants, T_END, executor=ex, chunk_size=2, threads=1)
    for a, b in zip(got, serial(variants)):
        assert_same(a, b)


def test_dask_cluster_of_processes_equals_serial(variants, five_bar, designs, circle):
    distributed = pytest.importorskip("distributed")
    mixed = [*variants[:3], (five_bar, {"q0": IMPOSSIBLE_Q0}), *variants[3:]]
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                  dashboard_address=None, silence_logs=40) as cluster, \
            distributed.Client(cluster) as client:
        got = simulate(mixed, T_END, executor=client, chunk_size=2, threads=1)
        efforts = inverse_dynamics(designs, circle, dt=ID_DT, executor=client, chunk_size=2, threads=1)
    expected = serial(variants)
    assert isinstance(got[3], BatchError) and got[3].type == "AssemblyError" and got[3].index == 3
    for a, b in zip(got[:3] + got[4:], expected):
        assert_same(a, b)
    assert_same_efforts(efforts, serial_inverse(designs, circle))


# ---------------------------------------------------------------------- inverse dynamics

ID_DT = 0.004  # s: 251 samples of a 1 s circle


@pytest.fixture(scope="module")
def circle(five_bar):
    home = robot.EndEffector(five_bar, "P").home()
    return robot.circle(home + [0.0, 0.05], 0.05, duration=1.0)


@pytest.fixture(scope="module")
def designs(five_bar):
    """Design variants of the five-bar on one circle: a heavier distal link, longer proximal
    links (the points C1, C2 moved out along them), and a right proximal link so short
    that the circle meets a singularity of that design."""
    heavy = sweep(five_bar, "bodies.distal_right.mass", [1.4])
    model = five_bar.to_dict()
    longer = []
    for scale in (1.02, 0.6):
        m = five_bar.to_dict()
        for a, c in (("A1", "C1"), ("A2", "C2")):
            A, C = np.array(model["points"][a]), np.array(model["points"][c])
            m["points"][c] = (A + scale * (C - A)).tolist()
        longer.append(m)
    return [five_bar, *heavy, *longer]


def serial_inverse(designs, path):
    """One call per design (no pool shared between them)."""
    return [inverse_dynamics([d], path, dt=ID_DT, threads=1)[0] for d in designs]


def assert_same_efforts(got, expected):
    assert len(got) == len(expected)
    for a, b in zip(got, expected):
        if isinstance(b, BatchError):
            assert (a.type, a.message) == (b.type, b.message)
            continue
        for name in ("t", "X", "q", "qd", "qdd", "tau", "sigma_I", "sigma_II", "condition"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), name


def test_inverse_dynamics_of_designs_on_a_path_equal_serial_and_solve_motion(designs, circle):
    got = inverse_dynamics(designs, circle, dt=ID_DT, threads=2)
    expected = serial_inverse(designs, circle)
    assert_same_efforts(got, expected)
    # The shortened proximal links cannot follow the circle: reported in place.
    assert isinstance(got[3], BatchError) and got[3].index == 3, got[3]
    assert got[3].type in ("SingularityError", "AssemblyError")
    # robot.solve_motion runs the same core stages: the same numbers, bit for bit.
    for k in range(3):
        ref = robot.solve_motion(robot.EndEffector(got[k].mech, "P"), circle, dt=ID_DT)
        for name in ("q", "qd", "qdd", "tau", "sigma_I", "sigma_II", "condition"):
            assert np.array_equal(getattr(got[k], name), getattr(ref, name)), name
    # Same kinematics, heavier link: same inputs, more effort.
    assert np.array_equal(got[0].q, got[1].q) and not np.array_equal(got[0].tau, got[1].tau)


def test_inverse_dynamics_of_coordinate_rows_equals_mechanism_inverse_dynamics(five_bar):
    res = five_bar.simulate(0.2, output_dt=0.01)
    variants = [(m, {"q": res.q, "qd": res.qd, "qdd": res.qdd}) for m in sweep(five_bar, "bodies.distal_left.parts.1.mass", [0.3, 0.5])]
    variants.append((five_bar, {"q": [[math.pi, 0.0]], "qd": [[0.0, 0.0]], "qdd": [[0.0, 0.0]]}))
    got = inverse_dynamics(variants, threads=2)
    for (mech, _), tau in zip(variants[:2], got):
        assert np.array_equal(tau, mech.inverse_dynamics(res.q, res.qd, res.qdd))
    # Forward then inverse: the model's own drive efforts back (0.3 kg: the simulated model).
    assert np.abs(got[0] - res.tau).max() < 1e-8
    assert isinstance(got[2], BatchError) and got[2].type == "AssemblyError"


def test_inverse_dynamics_failures_in_place(five_bar, designs, circle):
    bad = five_bar.to_dict()
    bad["bodies"]["proximal_left"]["mass"] = -1.0
    home = robot.EndEffector(five_bar, "P").home()
    through_singularity = robot.point_to_point(home, (home[0], 0.1), duration=1.0)
    mixed = [designs[0], bad, (five_bar, {"path": through_singularity}), (five_bar, {"point": "Q"}), five_bar]
    got = inverse_dynamics(mixed, circle, dt=ID_DT)
    assert isinstance(got[1], BatchError) and got[1].type == "ModelError" and "mass" in got[1].message
    assert got[2].type == "SingularityError" and "type II" in got[2].message and got[2].index == 2
    assert got[3].type == "ArgumentError" and got[3].message.startswith('point: expected one of the points A1, ')
    assert got[3].message.endswith('got "Q"')
    with pytest.raises(pd.SingularityError):
        robot.solve_motion(robot.EndEffector(five_bar, "P"), through_singularity)
    assert_same_efforts([got[0], got[4]], serial_inverse([designs[0], five_bar], circle))
    (no_motion,) = inverse_dynamics([five_bar])
    assert no_motion.type == "ArgumentError" and "needs a path" in no_motion.message


def test_inverse_dynamics_on_a_thread_pool_executor(designs, circle):
    with ThreadPoolExecutor(2) as ex:
        got = inverse_dynamics(designs, circle, dt=ID_DT, executor=ex, chunk_size=1, threads=1)
    assert_same_efforts(got, serial_inverse(designs, circle))


def test_sweep_edits_the_path(five_bar):
    ms = sweep(five_bar, "bodies.distal_right.mass", [0.5, 0.9])
    assert [m.masses[3] for m in ms] == [0.5, 0.9]
    qs = sweep(five_bar, "coordinates.theta1.q0", [1.9, 2.0], build=False)
    assert [m["coordinates"][0]["q0"] for m in qs] == [1.9, 2.0]

    def heavier_effector(model, scale):
        model["bodies"]["distal_left"]["parts"][1]["mass"] *= scale
        return model

    ms = sweep(five_bar, heavier_effector, [1.0, 2.0])
    assert ms[1].masses[2] - ms[0].masses[2] == pytest.approx(0.3)
    assert five_bar.masses[2] == ms[0].masses[2]  # the base is not changed


def test_monte_carlo_is_seeded(five_bar):
    dists = {"bodies.proximal_left.mass": (0.4, 0.6), "gravity.1": lambda rng, n: rng.normal(-9.81, 0.01, n)}
    ms, values = monte_carlo(five_bar, dists, 4, seed=7)
    again, values2 = monte_carlo(five_bar, dists, 4, seed=7)
    rng = np.random.default_rng(7)
    assert np.array_equal(values["bodies.proximal_left.mass"], rng.uniform(0.4, 0.6, 4))
    assert np.array_equal(values["gravity.1"], rng.normal(-9.81, 0.01, 4))
    assert ms == again
    assert [m.masses[0] for m in ms] == values["bodies.proximal_left.mass"].tolist()
    assert [m.gravity[1] for m in ms] == values["gravity.1"].tolist()


def test_ctrl_c_keeps_the_variants_finished_and_stops_the_rest():
    # Six 1e6 s four-bar runs (over two minutes of work each: 10 s costs about 1.5 ms) on 2
    # threads and a real SIGINT 0.3 s in: the binding checks for Ctrl-C every 0.1 s while
    # the pool works, the two runs under way stop at their next step with what they have
    # (within the first tenth of the run), the four not started are not run, and the
    # interrupt goes on (a KeyboardInterrupt) carrying them all.
    mech = pd.load_example("four-bar-gravity")
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(BatchInterrupted) as caught:
        simulate([mech] * 6, t_end=1e6, output_dt=0.1, threads=2)
    timer.join()
    results = caught.value.results
    assert isinstance(caught.value, KeyboardInterrupt) and len(results) == 6
    runs = [r for r in results if isinstance(r, pd.SimulationResult)]
    assert len(runs) == 2
    for r in runs:
        assert r.status == "cancelled" and "Ctrl-C" in r.message and 0 < r.t[-1] < 1e5
        assert np.isfinite(r.q).all() and np.allclose(np.diff(r.t[:-1]), 0.1, rtol=1e-9)
    assert [r.type for r in results if isinstance(r, BatchError)] == ["Cancelled"] * 4


def test_batch_motions_equal_mechanism_simulate(five_bar):
    # Speeds and tables by coordinate name, common or per variant, run without Python in the
    # loop and equal, bit for bit, mech.simulate with the same motion; the metadata reruns.
    table = {"t": [0.0, 0.1, 0.2, 0.3], "q": [1.0, 1.05, 1.08, 1.2]}
    variants = [five_bar, (five_bar, {"motion": {"theta2": table}})]
    out = simulate(variants, t_end=0.3, output_dt=0.05, motion={"theta1": 2.0})
    for r, motion in zip(out, [{"theta1": 2.0}, {"theta2": table}]):
        assert r.success, r
        alone = five_bar.simulate(t_end=0.3, output_dt=0.05, motion=motion)
        np.testing.assert_array_equal(r.q, alone.q)
        np.testing.assert_array_equal(r.tau, alone.tau)
        assert r.metadata["settings"]["motion"] == motion
        rerun = five_bar.simulate(**r.metadata["settings"])
        np.testing.assert_array_equal(rerun.q, r.q)
    # The first coordinate turns at 2 rad/s from its start.
    np.testing.assert_allclose(out[0].q[:, 0], five_bar.q0[0] + 2.0 * out[0].t, rtol=0, atol=1e-12)
    bad = simulate([(five_bar, {"motion": {"theta1": lambda t: (0.0, 0.0, 0.0)}})], t_end=0.1)
    assert isinstance(bad[0], BatchError) and "speeds or tables" in bad[0].message
