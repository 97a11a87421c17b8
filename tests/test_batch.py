"""Batch runs (planardyn.batch): native threads and a local Dask cluster of worker processes
both give, bit for bit, what a serial loop of Mechanism.simulate gives; a failing variant
is reported in its place without losing the others; sweep and monte_carlo make the variants
they say."""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from conftest import MODELS

import planardyn as pd
from planardyn.batch import BatchError, monte_carlo, simulate, sweep

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


def test_dask_cluster_of_processes_equals_serial(variants, five_bar):
    distributed = pytest.importorskip("distributed")
    mixed = [*variants[:3], (five_bar, {"q0": IMPOSSIBLE_Q0}), *variants[3:]]
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                  dashboard_address=None, silence_logs=40) as cluster, \
            distributed.Client(cluster) as client:
        got = simulate(mixed, T_END, executor=client, chunk_size=2, threads=1)
    expected = serial(variants)
    assert isinstance(got[3], BatchError) and got[3].type == "AssemblyError" and got[3].index == 3
    for a, b in zip(got[:3] + got[4:], expected):
        assert_same(a, b)


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
