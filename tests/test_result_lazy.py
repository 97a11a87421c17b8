"""A result of ``Mechanism.simulate`` makes its arrays, energy, counters, events and metadata at
their first read (issue 25 item 4: a short run's fixed cost), and holds then exactly what the
eager path gives: a batch run of the same variant converts every entry up front."""

from __future__ import annotations

import copy
import dataclasses
import pickle

import numpy as np
import planardyn as pd
from planardyn.batch import simulate as simulate_batch
from planardyn.result import LAZY_FIELDS

#: A passive five-bar run long enough to have several rows and steps (s).
T_END = 0.2


def assert_same_fields(a: pd.SimulationResult, b: pd.SimulationResult, skip: set[str]) -> None:
    for f in dataclasses.fields(a):
        if f.name in skip:
            continue
        x, y = getattr(a, f.name), getattr(b, f.name)
        if f.name == "energy":
            for e in dataclasses.fields(x):
                np.testing.assert_array_equal(getattr(x, e.name), getattr(y, e.name), err_msg=e.name)
        elif isinstance(x, np.ndarray):
            np.testing.assert_array_equal(x, y, err_msg=f.name)
        else:
            assert x == y, f.name


def test_a_result_makes_its_fields_at_first_read_and_equals_the_eager_one():
    mech = pd.load_example("five-bar")
    res = mech.simulate(T_END)
    made = set(vars(res))
    assert not made & LAZY_FIELDS, "nothing is made before it is read"
    # The same run from a batch, whose workers convert every entry: equal bit for bit (one
    # core run), fields read in any order.
    eager = simulate_batch([(mech, {})], T_END, threads=1)[0]
    assert len(res.t) == len(eager.t) > 2 and res.stats["naccept"] > 2
    assert_same_fields(res, eager, skip={"metadata", "sol"})
    assert res.q is res.q and res.poses.base is res.x  # made once; poses a view of x, as before
    assert res.metadata["model"] is mech.to_dict() or res.metadata["model"] == mech.to_dict()
    assert res.metadata["settings"]["t_end"] == T_END and res.metadata["kind"] == "simulation"


def test_a_lazy_result_pickles_and_copies_whole():
    mech = pd.load_example("five-bar")
    res = mech.simulate(T_END)
    back = pickle.loads(pickle.dumps(res))
    assert "_pending" not in vars(back) and set(vars(back)) == {f.name for f in dataclasses.fields(res)}
    assert_same_fields(back, res, skip=set())
    # The dense output (native, not made later: a field with a default) is shared by a copy.
    dense = mech.simulate(T_END, dense_output=True)
    assert copy.copy(dense).sol is dense.sol and dense.sol.t_max == T_END


def test_metadata_records_the_settings_as_given_at_the_call():
    # Made at its first read, it still records the caller's q0 as it was at the call.
    mech = pd.load_example("five-bar")
    q0 = np.array(mech.q0, dtype=float)
    res = mech.simulate(0.01, q0=q0)
    given = q0.tolist()
    q0[0] += 1.0
    assert res.metadata["settings"]["q0"] == given
