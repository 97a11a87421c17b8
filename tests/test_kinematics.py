"""Every call that continues from a configuration is bounded: at most 1e3 rad (or lengths of
the drawing) per call, the loader's bound on q0, so that no call runs for long (a target of
1e15 rad never returned) and the answer is the same whatever the route."""

from __future__ import annotations

import numpy as np
import planardyn as pd
import pytest

FAR = 1e15


@pytest.fixture(scope="module")
def crank():
    return pd.load_example("slider-crank")


@pytest.mark.parametrize("call", ["assemble", "kinematics", "mass_matrix", "energy", "forward", "inverse", "simulate"])
def test_a_far_target_is_refused_naming_the_bound(crank, call):
    q = np.array([FAR])
    calls = {
        "assemble": lambda: crank.assemble(q),
        "kinematics": lambda: crank.kinematics(q),
        "mass_matrix": lambda: crank.mass_matrix(q),
        "energy": lambda: crank.energy(q, [0.0]),
        "forward": lambda: crank.forward_dynamics(q, [0.0]),
        "inverse": lambda: crank.inverse_dynamics(q, [0.0], [0.0]),
        "simulate": lambda: crank.simulate(0.01, q0=q),
    }
    with pytest.raises(ValueError, match=r"within 1e3 \(rad") as err:
        calls[call]()
    assert getattr(err.value, "argument", "q") == "q"


def test_whole_turns_within_the_bound_come_back_to_the_same_pose(crank):
    # The slider-crank's crank turns fully: 100 turns on it is the same configuration
    # (continuation in 0.1 rad steps; each step converged to the position tolerance).
    x0 = crank.assemble(crank.q0)
    x100 = crank.assemble(crank.q0 + 200 * np.pi)
    phi = np.arange(x0.size) % 3 == 2
    assert np.max(np.abs(x100[~phi] - x0[~phi])) < 1e-9
    assert np.max(np.abs(np.angle(np.exp(1j * (x100[phi] - x0[phi]))))) < 1e-9
