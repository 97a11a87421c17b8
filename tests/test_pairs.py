"""The gear and pin-in-slot pairs from Python: the geared five-bar against its own
one-coordinate Lagrangian (closed-form positions, complex-step derivatives), the gear
train's exact ratios, the Scotch yoke's torque, the drawing geometry the core gives, and the
mobility counts (one row for each of these pairs)."""

from __future__ import annotations

import cmath
import math

import numpy as np
import planardyn as pd
import pytest
from conftest import MODELS
from planardyn import structure

G = 9.81
# geared-five-bar.yaml: base pivots, link lengths, gear radii, drawn crank angles.
A1, A2 = (-0.15, 0.0), (0.15, 0.0)
L1, L2 = 0.25, 0.35
R1, R2 = 0.12, 0.18
TH1_0, TH2_0 = math.radians(115.0), math.radians(60.0)
# Complex-step size: the derivative is exact to round-off for any small h (no cancellation).
CSTEP = 1e-30


def _points(th1):
    """C1, C2, P of the geared five-bar at crank angle th1 (complex-safe): th2 follows the
    gears, P is the upper intersection of the two distal circles."""
    th2 = TH2_0 - R1 / R2 * (th1 - TH1_0)
    c1 = (A1[0] + L1 * cmath.cos(th1), A1[1] + L1 * cmath.sin(th1))
    c2 = (A2[0] + L1 * cmath.cos(th2), A2[1] + L1 * cmath.sin(th2))
    dx, dy = c2[0] - c1[0], c2[1] - c1[1]
    d = cmath.sqrt(dx * dx + dy * dy)
    h = cmath.sqrt(L2 * L2 - d * d / 4)
    p = ((c1[0] + c2[0]) / 2 - h * dy / d, (c1[1] + c2[1]) / 2 + h * dx / d)
    return c1, c2, p


def _bars(th1):
    """(mass, end p, end q, point mass at q) of the five-bar's bodies: uniform bars, and the
    0.3 kg end-effector mass at P."""
    c1, c2, p = _points(th1)
    return [(0.5, A1, c1, 0.0), (0.5, A2, c2, 0.0), (0.7, c1, p, 0.3), (0.7, c2, p, 0.0)]


def _reduced(th1):
    """Generalized mass m(th1) and dV/dth1 of the one-coordinate reduction, with the
    velocities from complex-step derivatives of the closed-form positions."""
    z = complex(th1, CSTEP)
    mass, dv = 0.0, 0.0
    for (m, p, q, mq), (_, pz, qz, _) in zip(_bars(th1), _bars(z)):
        p, q = [complex(v).real for v in p], [complex(v).real for v in q]
        dp = [complex(v).imag / CSTEP for v in pz]
        dq = [complex(v).imag / CSTEP for v in qz]
        ex, ey = q[0] - p[0], q[1] - p[1]
        dex, dey = dq[0] - dp[0], dq[1] - dp[1]
        length2 = ex * ex + ey * ey
        omega = (ex * dey - ey * dex) / length2  # d(bar angle)/d(th1)
        vx, vy = (dp[0] + dq[0]) / 2, (dp[1] + dq[1]) / 2
        mass += m * (vx * vx + vy * vy) + m * length2 / 12 * omega**2 + mq * (dq[0] ** 2 + dq[1] ** 2)
        dv += G * (m * vy + mq * dq[1])
    return mass, dv


def test_geared_five_bar_matches_its_one_coordinate_lagrangian():
    mech = pd.load(MODELS / "geared-five-bar.yaml")
    assert mech.dof == 1
    h = 1e-5  # central difference of m(th1): error h^2 m''' / 6, about 1e-11 relative here
    for th1, th1d in [(TH1_0, 0.0), (TH1_0 + 0.2, 1.5), (TH1_0 - 0.3, -2.0)]:
        # Positions: the core's P against the closed form.
        k = mech.kinematics([th1])
        p = k["points"][mech.point_names.index("P")]
        np.testing.assert_allclose(p, [v.real for v in _points(th1)[2]], rtol=0, atol=1e-13)
        m, dv = _reduced(th1)
        dm = (_reduced(th1 + h)[0] - _reduced(th1 - h)[0]) / (2 * h)
        # Lagrange: m th1'' + m'/2 th1'^2 + dV/dth1 = 0 (no drive, no damping).
        qdd = -(dm / 2 * th1d**2 + dv) / m
        assert mech.mass_matrix([th1])[0, 0] == pytest.approx(m, rel=1e-12)
        assert mech.forward_dynamics([th1], [th1d])[0] == pytest.approx(qdd, rel=1e-8)


def test_gear_train_ratios_from_python_are_exact():
    mech = pd.load(MODELS / "gear-train.yaml")
    u = mech.kinematics([0.9])["u"][:, :, 0]  # (n, 3): d(X, Y, phi)/d(theta)
    wheel = -0.02 / 0.06
    assert u[1, 2] == pytest.approx(wheel, abs=1e-15)
    assert u[2, 2] == pytest.approx(wheel * 0.025 / 0.045, abs=1e-15)
    assert u[3, 0] == pytest.approx(0.02, abs=1e-15)
    # One row for each gear pair: 3*4 - (4 pairs * 2 + 3 gears * 1) = 1.
    assert [p["rows"] for p in mech.pairs][-3:] == [(8, 9), (9, 10), (10, 11)]
    s = structure.analyse(mech)
    assert (s.grubler, s.rank, s.mobility, s.redundant) == (1, 11, 1, 0)


def test_scotch_yoke_torque_from_python():
    """tau = (J_O + m_y r^2 sin^2) th'' + m_y r^2 sin cos th'^2 + m_c g (r/2) cos, the yoke's
    Lagrangian with x = r cos(theta), J_O = m_c r^2 / 3."""
    mech = pd.load(MODELS / "scotch-yoke.yaml")
    r, mc, my = 0.1, 0.5, 1.2
    th, thd, thdd = 0.8, -3.0, 2.0
    s, c = math.sin(th), math.cos(th)
    tau = (mc * r * r / 3 + my * r * r * s * s) * thdd + my * r * r * s * c * thd**2 + mc * G * r / 2 * c
    assert mech.inverse_dynamics([th], [thd], [thdd])[0] == pytest.approx(tau, rel=1e-12)


def test_pair_geometry_is_what_the_drawings_show():
    yoke = pd.load(MODELS / "scotch-yoke.yaml")
    th = 1.1
    x = yoke.kinematics([th])["x"]
    geo = {g["name"]: g for g in yoke.pair_geometry(x)}
    assert [g["kind"] for g in geo.values()] == ["revolute", "slot", "prismatic"]
    # The slot is vertical at the pin's x = r cos(theta), from S1 to S2 (0.24 m long).
    (x0, y0), (x1, y1) = geo["pin"]["lines"][0]
    assert x0 == pytest.approx(0.1 * math.cos(th), abs=1e-14) and x1 == pytest.approx(x0, abs=1e-15)
    assert y1 - y0 == pytest.approx(0.24, abs=1e-14)
    assert geo["pin"]["pins"][0] == pytest.approx((0.1 * math.cos(th), 0.1 * math.sin(th)), abs=1e-14)
    train = pd.load(MODELS / "gear-train.yaml")
    geo = {g["name"]: g for g in train.pair_geometry(train.kinematics([0.4])["x"])}
    assert geo["mesh1"]["circles"] == [((0.0, 0.0), 0.02), ((0.08, 0.0), pytest.approx(0.06))]
    assert [r for _, r in geo["mesh2"]["circles"]] == pytest.approx([0.025, 0.045])
    (p, q), = geo["rack_mesh"]["lines"]
    assert p[1] == pytest.approx(-0.02, abs=1e-15) and q[0] - p[0] == pytest.approx(0.2, abs=1e-14)


def test_a_gear_pair_cannot_be_a_coordinate():
    text = (MODELS / "gear-train.yaml").read_text().replace("pair: pinion_shaft", "pair: mesh1")
    with pytest.raises(pd.ModelError, match=r"coordinates\[0\]\.pair.*no relative coordinate"):
        pd.loads(text, "yaml")
