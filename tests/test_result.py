"""What users ask of a trajectory: pair reactions along a run, the motion of named points,
the drives' power, and a table indexed by t; each against a closed form."""

from __future__ import annotations

import math
from decimal import Decimal, localcontext

import numpy as np
import planardyn as pd
import pytest
from conftest import (
    FOUR_BAR_A,
    FOUR_BAR_B,
    FOUR_BAR_C,
    FOUR_BAR_D,
    PENDULUM_I,
    PENDULUM_L,
    PENDULUM_M,
    G,
    four_bar_B,
)
from scipy.integrate import cumulative_simpson


def test_pendulum_pin_reaction_along_a_swing(pendulum):
    # Released at 1 rad: the pin force on the bob is m (a_cm - g), with the centre at
    # l (sin q, -cos q) and qdd = -m g l sin q / (I + m l^2) (the one-coordinate equation),
    # computed here from q and qd alone.
    res = pendulum.simulate(t_end=2.0, q0=[1.0], output_dt=0.01, rtol=1e-11, atol=1e-12)
    r = pendulum.reactions(res)
    assert r.shape == (len(res.t), 1, 3)
    q, qd = res.q[:, 0], res.qd[:, 0]
    m, l = PENDULUM_M, PENDULUM_L
    qdd = -m * G * l * np.sin(q) / (PENDULUM_I + m * l * l)
    ax = l * (np.cos(q) * qdd - np.sin(q) * qd**2)
    ay = l * (np.sin(q) * qdd + np.cos(q) * qd**2)
    # Round-off of the reaction solve: 1e-12 of the weight (19.6 N).
    np.testing.assert_allclose(r[:, 0, 0], m * ax, rtol=0, atol=2e-11)
    np.testing.assert_allclose(r[:, 0, 1], m * ay + m * G, rtol=0, atol=2e-11)
    np.testing.assert_array_equal(r[:, 0, 2], 0.0)  # a revolute pair transmits no couple
    # Each row equals the one-state call at that row's q, qd, tau.
    k = 57
    np.testing.assert_allclose(r[k], pendulum.reactions(res.q[k], res.qd[k], t=res.t[k], tau=res.tau[k]),
                               rtol=1e-13, atol=1e-13)


def _decimal_cos_sin(x: Decimal) -> tuple[Decimal, Decimal]:
    # Taylor series to 45 digits (|x| < 8 here: 60 terms at most).
    c, s, ct, st, i = Decimal(0), Decimal(0), Decimal(1), x, 0
    while abs(ct) > Decimal("1e-45") or abs(st) > Decimal("1e-45"):
        c, s = c + ct, s + st
        ct, st = -ct * x * x / ((2 * i + 1) * (2 * i + 2)), -st * x * x / ((2 * i + 2) * (2 * i + 3))
        i += 1
    return c, s


def _four_bar_B_derivatives(theta: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """B and its first two theta derivatives from conftest.four_bar_B's closed form evaluated
    at 40 digits, by five-point central differences with step 1e-6 rad (truncation ~h^4 =
    1e-24, round-off 1e-40 / h^2 = 1e-28): exact to double precision."""
    with localcontext() as ctx:
        ctx.prec = 40
        a, b, c, d = (Decimal(v) for v in (FOUR_BAR_A, FOUR_BAR_B, FOUR_BAR_C, FOUR_BAR_D))

        def B(th: Decimal) -> list[Decimal]:
            co, si = _decimal_cos_sin(th)
            ax, ay = a * co, a * si
            dx, dy = d - ax, -ay
            e = (dx * dx + dy * dy).sqrt()
            along = (b * b - c * c + e * e) / (2 * e)
            h = (b * b - along * along).sqrt()
            return [ax + (along * dx - h * dy) / e, ay + (along * dy + h * dx) / e]

        h, t = Decimal("1e-6"), Decimal(theta)
        b2, b1, b0, a1, a2 = (B(t + j * h) for j in (2, 1, 0, -1, -2))
        d1 = [(-p2 + 8 * p1 - 8 * m1 + m2) / (12 * h) for p2, p1, m1, m2 in zip(b2, b1, a1, a2)]
        d2 = [(-p2 + 16 * p1 - 30 * p0 + 16 * m1 - m2) / (12 * h * h)
              for p2, p1, p0, m1, m2 in zip(b2, b1, b0, a1, a2)]
        return tuple(np.array([float(v) for v in vs]) for vs in (b0, d1, d2))  # type: ignore[return-value]


def test_four_bar_coupler_point_against_its_closed_form_path(four_bar):
    # B is on the circles |B - A| = b and |B - D| = c (conftest.four_bar_B); its velocity is
    # dB/dtheta thetad and its acceleration d2B/dtheta2 thetad^2 + dB/dtheta thetadd, the
    # theta derivatives of the closed form exact to double precision (_four_bar_B_derivatives).
    # Bounds: the point motion's own round-off, measured 2.3e-14 m, 2.5e-12 m/s and 1.6e-11
    # m/s^2 (|B''| thetad^2 up to 170 m/s^2 here).
    res = four_bar.simulate(t_end=1.0, output_dt=0.02, drives=lambda t, q, qd: [2.0], rtol=1e-11, atol=1e-12)
    pm = four_bar.point_motion(res)
    assert pm.names == ["O", "A", "B", "D"] and pm.position.shape == (len(res.t), 4, 2)
    pos, vel, acc = pm["B"]

    for k, (th, thd, thdd) in enumerate(zip(res.q[:, 0], res.qd[:, 0], res.qdd[:, 0])):
        b0, d1, d2 = _four_bar_B_derivatives(float(th))
        np.testing.assert_allclose(b0, four_bar_B(th), rtol=0, atol=1e-15)  # the same closed form
        np.testing.assert_allclose(pos[k], b0, rtol=0, atol=1e-12)
        np.testing.assert_allclose(vel[k], d1 * thd, rtol=0, atol=1e-10)
        np.testing.assert_allclose(acc[k], d2 * thd**2 + d1 * thdd, rtol=0, atol=1e-9)
    # The ground points stand still; A turns on the crank circle.
    assert np.all(pm["O"][0] == 0.0) and np.all(pm["D"][1] == 0.0)
    np.testing.assert_allclose(np.hypot(*pm["A"][0].T), 0.3, rtol=1e-13)
    df = pm.to_dataframe()
    assert df.index.name == "t" and df["B_vx"].to_numpy().tolist() == vel[:, 0].tolist()


def test_drive_power_integrates_to_the_work(four_bar):
    # The model's only non-conservative force is the drive: its power tau * qd integrates to
    # the work column (the integrator's own quadrature state). Simpson's rule on the output
    # grid differs from it by 1.9e-7, 1.2e-8 and 7.5e-10 J at 2, 1 and 0.5 ms: 16 times less
    # per halving, Simpson's own h^4 error, so the bound at 1 ms is 2.5e-8 J.
    res = four_bar.simulate(t_end=1.0, output_dt=0.001, drives=lambda t, q, qd: [2.0 * math.cos(3 * t)],
                            rtol=1e-11, atol=1e-12)
    p = res.power[:, 0]
    assert np.all(p == res.tau[:, 0] * res.qd[:, 0])
    w = cumulative_simpson(p, x=res.t, initial=0.0)
    np.testing.assert_allclose(w, res.energy.work, rtol=0, atol=2.5e-8)
    df = res.to_dataframe()
    assert df.index.name == "t" and np.all(df.index.to_numpy() == res.t)
    assert np.all(df["power_theta"].to_numpy() == p)


def test_along_a_result_errors_name_the_call(four_bar, pendulum):
    res = pendulum.simulate(t_end=0.1)
    with pytest.raises(ValueError, match="not a run of this mechanism"):
        four_bar.reactions(res)
    with pytest.raises(TypeError, match="result alone"):
        pendulum.reactions(res, res.qd)
    with pytest.raises(TypeError, match="needs qd"):
        pendulum.reactions(res.q[0])


def test_a_singular_row_is_refused_with_its_row_and_time():
    # The slider-driven slider-crank pushed through its dead centre (at 0.4 m): the row at the
    # dead centre is below SINGULAR_SIGMA; the error names it.
    mech = pd.load_example("library/slider-crank-slider-driven")
    t = np.array([0.0, 1.0, 2.0])
    q = np.array([[0.35], [0.4], [0.35]])
    x = np.stack([mech.assemble(qk) for qk in q])
    res = pd.SimulationResult.from_raw(
        {"t": t, "q": q, "qd": np.zeros((3, 1)), "qdd": np.zeros((3, 1)), "tau": np.zeros((3, 1)), "x": x,
         "xd": np.zeros_like(x), "kinetic": np.zeros(3), "potential": np.zeros(3), "work": np.zeros(3),
         "sigma": np.zeros(3), "residual": np.zeros(3), "partitioned": np.zeros(3, bool), "status": "success",
         "message": "", "stats": {}},
        coordinate_names=mech.coordinate_names, coordinate_kinds=mech.coordinate_kinds, body_names=mech.body_names)
    with pytest.raises(pd.SingularityError, match=r"row 1 \(t = 1 s\)") as err:
        mech.reactions(res)
    assert err.value.row == 1 and err.value.t == 1.0 and err.value.kind == "type_ii"


def test_pin_force_plot_draws_the_reaction(four_bar):
    # One call: |F| against t, and the polar diagram of the force on the coupler at the
    # elbow, in the coupler's frame; the plotted values are the reactions' own.
    from planardyn.plot import plot_reaction

    res = four_bar.simulate(t_end=0.5, output_dt=0.01)
    lines = plot_reaction(four_bar, res, "elbow")
    f = four_bar.reactions(res)[:, four_bar.pair_names.index("elbow"), :2]
    np.testing.assert_allclose(lines[0].get_ydata(), np.hypot(*f.T), rtol=1e-15)
    phi = res.poses[:, four_bar.body_names.index("coupler"), 2]
    np.testing.assert_allclose(lines[1].get_xdata(), np.arctan2(f[:, 1], f[:, 0]) - phi, rtol=1e-15)
    with pytest.raises(ValueError, match="no pair 'hinge'"):
        plot_reaction(four_bar, res, "hinge")
