"""planardyn.robot: task-space motions, sizing, singularity maps, workspaces, and the
computed-torque example. Tolerances are named with where they come from."""

from __future__ import annotations

import math
import runpy

import numpy as np
import planardyn as pd
import pytest
from conftest import MODELS, ROOT
from planardyn import robot

# Central differences with h = 1e-6 on positions solved to ~1e-12 L: error ~ 1e-12/1e-6.
FD_TOL = 1e-7
# Second differences with h = 1e-4: truncation ~ h^2 |X''''| ~ 1e-8, round-off 1e-12/h^2.
FD2_TOL = 1e-6
# Required: the drive torques reproduce the circle in open-loop forward
# dynamics to 1e-6 m (measured: ~3e-10 m five-bar, ~2e-10 m 3-RRR).
RECOVER_TOL = 1e-6


@pytest.fixture(scope="module")
def five():
    return robot.EndEffector(pd.load(MODELS / "five-bar.yaml"), "P")


@pytest.fixture(scope="module")
def rrr():
    return robot.EndEffector(pd.load(MODELS / "3-rrr.yaml"), "P")


@pytest.mark.parametrize("which", ["five", "rrr"])
def test_jacobian_and_convective_term_match_finite_differences(which, request):
    ee = request.getfixturevalue(which)
    m = ee.mech.dof
    q = ee.mech.drawn_q + 0.05
    qd = np.linspace(0.5, 1.2, m)
    st = ee.state(q)
    h = 1e-6
    J_fd = np.column_stack([(ee.state(q + h * e).X - ee.state(q - h * e).X) / (2 * h) for e in np.eye(m)])
    assert np.abs(st.J - J_fd).max() < FD_TOL
    h = 1e-4  # d2/dt2 X(q + qd t) at t = 0 is d2X/dq2 [qd, qd]
    acc_fd = (ee.state(q + qd * h).X - 2 * st.X + ee.state(q - qd * h).X) / h**2
    assert np.abs(ee.convective(st.kin, qd) - acc_fd).max() < FD2_TOL


def test_time_laws_start_and_end_at_rest():
    for kind in ("quintic", "trapezoid"):
        s, sd, sdd = robot.time_law(kind, np.array([0.0, 0.5, 1.0]))
        assert s.tolist() == pytest.approx([0.0, 0.5, 1.0]) and sd[[0, 2]].tolist() == [0.0, 0.0]
    tau = np.linspace(0, 1, 20001)
    for kind in ("quintic", "trapezoid", "constant"):  # sd is the derivative of s
        s, sd, _ = robot.time_law(kind, tau)
        assert np.abs(np.gradient(s, tau)[1:-1] - sd[1:-1]).max() < 1e-3


def test_circle_and_table_paths_have_exact_derivatives():
    path = robot.circle((0.1, 0.2), 0.05, 2.0, profile="constant")
    t = np.array([0.3])
    X, Xd, Xdd = path.sample(t)
    assert np.linalg.norm(X[0] - [0.1, 0.2]) == pytest.approx(0.05)
    w = 2 * np.pi / 2.0  # rad/s: uniform speed, centripetal acceleration r w^2
    assert np.linalg.norm(Xd[0]) == pytest.approx(0.05 * w)
    assert np.linalg.norm(Xdd[0]) == pytest.approx(0.05 * w**2)
    tt = np.linspace(0, 1, 11)
    tab = robot.table(tt, np.column_stack([tt**2, tt]))  # not-a-knot ends: x = t^2 exactly
    assert tab.duration == 1.0 and tab.sample(0.5)[0].shape == (1, 2)
    # Not-a-knot cubic splines reproduce any cubic, so x = t^2 and its derivatives to round-off.
    X, Xd, Xdd = tab.sample(np.array([0.0, 0.55, 1.0]))
    np.testing.assert_allclose(X[:, 0], [0.0, 0.3025, 1.0], atol=1e-14)
    np.testing.assert_allclose(Xd, [[0.0, 1.0], [1.1, 1.0], [2.0, 1.0]], atol=1e-12)
    np.testing.assert_allclose(Xdd, [[2.0, 0.0]] * 3, atol=1e-10)


@pytest.mark.parametrize("which", ["five", "rrr"])
def test_circle_torques_drive_the_forward_dynamics_round_the_circle(which, request):
    ee = request.getfixturevalue(which)
    home = ee.home()
    angle = None if ee.dim == 2 else (0.0, 0.2)  # the 3-RRR platform also turns by 0.2 rad
    path = robot.circle(home[:2] + [0.0, 0.05], 0.05, duration=1.0, angle=angle)
    motion = robot.solve_motion(ee, path, dt=2e-3)
    assert motion.q.shape == (501, ee.mech.dof) and np.isfinite(motion.tau).all()
    # The inputs satisfy the task: X(q) = X* exactly, and J qd = Xd.
    assert np.abs(motion.task_of(motion.q[::50]) - motion.X[::50]).max() < 1e-10
    res = motion.simulate(rtol=1e-10, atol=1e-12)
    assert res.success, res.message
    assert np.abs(motion.task_of(res.q) - motion.X).max() < RECOVER_TOL


def test_motion_through_a_type_II_singularity_is_refused(five):
    home = five.home()
    # Straight down from the drawing: the distal links line up (C1, P, C2 collinear) near y = 0.15 m.
    with pytest.raises(pd.SingularityError, match=r"type II \(parallel\) singularity") as info:
        robot.solve_motion(five, robot.point_to_point(home, (home[0], 0.1), duration=1.0))
    exc = info.value
    assert exc.kind == "II" and exc.sigma < robot.SINGULAR_TOL and 0.5 < exc.t < 0.9
    assert "t = " in str(exc) and "end effector P at" in str(exc)
    assert len(exc.partial.t) > 100 and exc.partial.t[-1] <= exc.t
    assert exc.partial.tau.shape == exc.partial.q.shape


def test_motion_out_of_reach_stops_at_a_type_I_singularity(five):
    home = five.home()
    with pytest.raises(pd.SingularityError, match="type I") as info:
        robot.solve_motion(five, robot.line(home, (home[0], 0.7), duration=1.0), dt=5e-3)
    assert info.value.kind == "I" and info.value.X[1] == pytest.approx(0.577, abs=2e-3)


def test_sizing_report(five):
    path = robot.point_to_point(five.home(), five.home() + [0.05, 0.03], duration=0.5)
    rep = robot.size(five, path, dt=2e-3)
    # The peaks between the samples: those of the motion sampled 100 times finer, to 1e-6
    # (the resampling around each sampled peak, 64 times finer, finds them to (2 dt / 64)^2
    # times their curvature); the RMS by Simpson's rule to 1e-6 of it.
    m = robot.solve_motion(five, path, dt=2e-5)
    for k, d in enumerate(rep.drives):
        assert d.peak_effort == pytest.approx(np.abs(m.tau[:, k]).max(), rel=1e-6)
        assert d.peak_speed == pytest.approx(np.abs(m.qd[:, k]).max(), rel=1e-6)
        assert d.peak_power == pytest.approx(np.abs(m.tau[:, k] * m.qd[:, k]).max(), rel=1e-6)
        assert d.rms_effort == pytest.approx(np.sqrt(np.trapezoid(m.tau[:, k] ** 2, m.t) / m.t[-1]), rel=1e-6)
        assert d.rms_effort <= d.peak_effort
        assert np.all(np.diff(d.envelope_effort) <= 0) and np.all(np.diff(d.envelope_speed) >= 0)
    assert rep.min_sigma_II[0] == pytest.approx(m.sigma_II.min(), rel=1e-6)
    heavy = robot.size(five, path, payload=1.0, dt=2e-3)
    # A 1 kg payload at P, 0.45 m above the base, adds about 1 kg * 9.81 * lever to the holding torques.
    assert heavy.drives[0].rms_effort > rep.drives[0].rms_effort + 0.3
    assert "payload 1 kg" in str(heavy) and heavy.to_dict()["drives"][0]["name"] == "theta1"


def test_payload_is_a_point_mass_part(five):
    mech = robot.with_payload(five.mech, "P", 0.4)
    assert mech.masses.sum() == pytest.approx(five.mech.masses.sum() + 0.4)


def test_singularity_map_finds_the_type_II_locus(five):
    grid = robot.singularity_map(five, (-0.3, 0.3), (0.05, 0.6), n=25)
    assert grid.reachable[np.argmin(np.abs(grid.y - 0.45)), np.argmin(np.abs(grid.x - 0.014))]
    assert np.nanmin(grid.sigma_II) < 0.05  # the locus just above the base (the refused line's)
    assert 0.1 < grid.area < 0.33  # m^2: part of the 0.6 x 0.55 m box


def _two_r_arm(l1: float, l2: float) -> dict:
    return {
        "name": "2R arm", "gravity": [0, 0],
        "points": {"O": [0, 0], "A": [l1, 0], "B": [l1, l2]}, "ground": ["O"],
        "bodies": {"upper": {"points": ["O", "A"], "uniform_bar": ["O", "A"], "mass": 1.0},
                   "fore": {"points": ["A", "B"], "uniform_bar": ["A", "B"], "mass": 1.0}},
        "pairs": [{"type": "revolute", "name": "shoulder", "at": "O", "bodies": ["ground", "upper"]},
                  {"type": "revolute", "name": "elbow", "at": "A", "bodies": ["upper", "fore"]}],
        "coordinates": [{"name": "q1", "pair": "shoulder", "value": 0.0},
                        {"name": "q2", "pair": "elbow", "value": math.pi / 2}],
    }


def test_workspace_of_a_two_r_arm_is_its_annulus():
    l1, l2 = 0.3, 0.2
    ee = robot.EndEffector(pd.from_dict(_two_r_arm(l1, l2)), "B")
    # Shoulder over a half turn, elbow on one side (0..pi): a half annulus, area pi/2 (R^2 - r^2).
    ws = robot.workspace(ee, [[0.0, math.pi], [0.0, math.pi]], n=60, cells=100)
    exact = math.pi / 2 * ((l1 + l2) ** 2 - (l1 - l2) ** 2)
    # The occupancy grid counts whole cells on the boundary: ~ perimeter * cell / 2.
    assert ws.area == pytest.approx(exact, rel=0.05)
    assert np.nanmax(ws.dexterity) <= 1 and np.nanmin(ws.dexterity) < 0.1  # stretched arm: type I
    assert len(ws.boundary()) >= 1


def test_plots_draw(five, tmp_path):
    from matplotlib.figure import Figure

    motion = robot.solve_motion(five, robot.point_to_point(five.home(), five.home() + [0.03, 0], 0.2), dt=5e-3)
    for plot, obj in ((robot.plot_motion, motion), (robot.plot_sizing, robot.size(motion)),
                      (robot.plot_singularity_map, robot.singularity_map(five, (-0.2, 0.2), (0.3, 0.6), n=8))):
        fig = Figure()
        assert plot(obj, fig)
        fig.savefig(tmp_path / "x.png")


def test_computed_torque_example_tracks_the_circle(capsys):
    # examples/04 asserts max error < 1e-3 m after the transient; it prints the number.
    runpy.run_path(str(ROOT / "examples" / "04_computed_torque.py"), run_name="__main__")
    out = capsys.readouterr().out
    max_um = float(out.split("tracking error after")[1].split("max")[1].split("um")[0])
    assert max_um < 1000.0


def test_size_cli(tmp_path, capsys):
    model = str(MODELS / "five-bar.yaml")
    out = tmp_path / "size.json"
    code = robot.size_cli([model, "--circle", "0.014", "0.51", "0.06", "--payload", "0.5", "--dt", "0.005",
                           "--json", str(out)])
    assert code == 0 and "peak effort" in capsys.readouterr().out
    import json

    assert json.loads(out.read_text())["payload_kg"] == 0.5
    assert robot.size_cli([model, "--line", "0.014", "0.45", "0.014", "0.1", "--dt", "0.005"]) == 1
    assert "type II" in capsys.readouterr().err
    assert robot.size_cli([str(tmp_path / "missing.yaml"), "--line", "0", "0", "1", "1"]) == 2
    assert robot.size_cli([model]) == 2


def test_a_formula_path_and_its_table_agree_at_the_ends(five):
    # A motion that starts and ends moving: X = home + r (sin w t, 1 - cos w t), one turn of
    # a circle at constant speed r w = 0.19 m/s. As functions its derivatives are exact; a
    # table of 201 samples with the default (not-a-knot) ends gives the same efforts to the
    # spline's h^2 accuracy, where clamped ends (the former default) invent a stop at t = 0
    # and t = 1 and are off by orders of magnitude there.
    home, r, w = five.home()[:2], 0.03, 2 * np.pi

    def X(t):
        return home + r * np.column_stack([np.sin(w * t), 1 - np.cos(w * t)])

    def Xd(t):
        return r * w * np.column_stack([np.cos(w * t), np.sin(w * t)])

    def Xdd(t):
        return r * w * w * np.column_stack([-np.sin(w * t), np.cos(w * t)])

    exact = robot.solve_motion(five, robot.from_functions(X, Xd, Xdd, 1.0), dt=5e-3)
    tt = np.linspace(0.0, 1.0, 201)
    tab = robot.solve_motion(five, robot.table(tt, X(tt)), dt=5e-3)
    clamped = robot.solve_motion(five, robot.table(tt, X(tt), bc_type="clamped"), dt=5e-3)
    scale = np.abs(exact.tau).max()
    ends = [0, -1]
    # Cubic spline with h = 5 ms: the acceleration's error ~ h^2 |X''''| / 12 = 1e-4 m/s^2
    # against r w^2 = 1.2 m/s^2, so ~1e-4 of the efforts (measured 3.4e-5); clamped ends
    # were off by 5.7 times the largest effort.
    assert np.abs(tab.tau - exact.tau).max() < 2e-4 * scale
    assert np.abs(clamped.tau[ends] - exact.tau[ends]).max() > 1.0 * scale


def test_formula_derivatives_are_checked(five):
    home = five.home()[:2]

    def X(t):
        return home + 0.02 * np.column_stack([np.sin(t), t])

    def Xd(t):
        return 0.02 * np.column_stack([-np.cos(t), np.ones_like(t)])  # wrong sign

    def Xdd(t):
        return 0.02 * np.column_stack([-np.sin(t), np.zeros_like(t)])

    with pytest.raises(ValueError, match="Xd.t. is not the time derivative"):
        robot.from_functions(X, Xd, Xdd, 1.0)
    with pytest.raises(ValueError, match="shape"):
        robot.from_functions(lambda t: np.zeros(len(t)), Xd, Xdd, 1.0)
