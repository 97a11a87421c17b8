"""The exact derivatives of forward and inverse dynamics through the Python API, against
4th-order central differences of forward_dynamics / inverse_dynamics (the Rust tests check
every model to 1e-8 with 8th-order differences; here the binding, on the 5R with springs)."""

from __future__ import annotations

import numpy as np
import planardyn
from conftest import MODELS


def central(f, x, h):
    cols = []
    for k in range(len(x)):
        e = np.zeros_like(x)
        e[k] = h
        cols.append((8 * (f(x + e) - f(x - e)) - (f(x + 2 * e) - f(x - 2 * e))) / (12 * h))
    return np.array(cols).T


def test_derivatives_through_the_binding_match_central_differences() -> None:
    # Truncation h^4 f^(5) / 30 with h = 1e-3 and round-off 1e-16 / h: 1e-9 of the scale.
    mech = planardyn.load(MODELS / "five-bar.yaml")
    q, qd, tau = mech.drawn_q + [0.05, -0.04], np.array([0.7, -0.3]), np.array([0.4, -0.2])
    fd = mech.forward_dynamics_derivatives(q, qd, tau=tau)
    assert np.array_equal(fd["qdd"], mech.forward_dynamics(q, qd, tau=tau))
    for key, f in [("dq", lambda v: mech.forward_dynamics(v, qd, tau=tau)),
                   ("dqd", lambda v: mech.forward_dynamics(q, v, tau=tau)),
                   ("dtau", lambda v: mech.forward_dynamics(q, qd, tau=v))]:
        ref = central(f, {"dq": q, "dqd": qd, "dtau": tau}[key], 1e-3)
        assert fd[key].shape == (2, 2)
        assert np.abs(fd[key] - ref).max() <= 1e-8 * np.abs(ref).max(), key
    qdd = np.array([1.3, 0.4])
    inv = mech.inverse_dynamics_derivatives(q, qd, qdd)
    assert np.allclose(inv["tau"], mech.inverse_dynamics(q, qd, qdd), rtol=0, atol=1e-12)
    assert np.allclose(inv["dqdd"], mech.mass_matrix(q), rtol=1e-14, atol=0)
    for key, f, x in [("dq", lambda v: mech.inverse_dynamics(v, qd, qdd), q),
                      ("dqd", lambda v: mech.inverse_dynamics(q, v, qdd), qd)]:
        ref = central(f, x, 1e-3)
        assert np.abs(inv[key] - ref).max() <= 1e-8 * np.abs(ref).max(), key
    # Forward and inverse derivatives are one residual: dqdd/dq = -A^-1 dtau/dq at this qdd.
    inv = mech.inverse_dynamics_derivatives(q, qd, fd["qdd"])
    assert np.allclose(fd["dq"], -np.linalg.solve(inv["dqdd"], inv["dq"]), rtol=1e-12, atol=1e-12)
