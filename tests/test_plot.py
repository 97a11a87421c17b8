"""Plot helpers and the GIF/MP4 animations.

Helpers draw on the ``ax`` given and return the artists; the data of the returned lines is
compared with the result's arrays. Nothing may change matplotlib's global style.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np
import planardyn as pd
import pytest
from conftest import MODELS
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from PIL import Image
from planardyn.animate import frame_indices, render_frames
from planardyn.plot import (
    default_trace_points,
    draw_mechanism,
    draw_mechanism_at,
    pivot_points,
    plot_coordinates,
    plot_efforts,
    plot_point_motion,
    plot_point_paths,
    plot_results,
    plot_torque_speed,
)


@pytest.fixture(scope="module")
def five_bar():
    mech = pd.load(MODELS / "five-bar.yaml")
    return mech, mech.simulate(t_end=0.4)


@pytest.fixture(scope="module")
def slider_crank():
    mech = pd.load(MODELS / "slider-crank.yaml")
    return mech, mech.simulate(t_end=0.3, output_dt=0.01)


def test_point_paths_follow_the_points(five_bar):
    mech, res = five_bar
    assert default_trace_points(mech) == ["C1", "C2", "P"]  # the moving joints of the loop
    ax = Figure().add_subplot()
    lines = plot_point_paths(mech, res, ["P"], ax=ax)
    assert len(lines) == 1
    xy = np.column_stack(lines[0].get_data())
    np.testing.assert_array_equal(xy, mech.point_positions(res.x)[:, mech.point_names.index("P"), :])
    with pytest.raises(ValueError, match="unknown point"):
        plot_point_paths(mech, res, ["Z"], ax=ax)


def test_mechanism_at_a_time_labels_and_title(five_bar):
    mech, res = five_bar
    ax = Figure().add_subplot()
    artists = draw_mechanism_at(mech, res, 0.2, ax=ax)
    k = int(np.argmin(np.abs(res.t - 0.2)))
    assert ax.get_title() == f"{mech.name}, t = {res.t[k]:.4g} s"
    labels = {a.get_text() for a in artists if isinstance(a, matplotlib.text.Annotation)}
    assert labels == set(mech.point_names)
    # The bar of the first body ends at its two points at that time.
    pts = mech.point_positions(res.x[k])
    bar = [a for a in artists if isinstance(a, matplotlib.lines.Line2D) and len(a.get_xdata()) == 2][0]
    np.testing.assert_allclose(np.column_stack(bar.get_data()), pts[[0, 2]])  # A1, C1


def test_torque_speed(five_bar):
    mech, res = five_bar
    ax = Figure().add_subplot()
    lines = plot_torque_speed(res, ax=ax)
    curves = [ln for ln in lines if len(ln.get_xdata()) == len(res.t)]
    assert len(curves) == 2
    for k, ln in enumerate(curves):
        np.testing.assert_array_equal(ln.get_xdata(), res.qd[:, k])
        np.testing.assert_array_equal(ln.get_ydata(), res.tau[:, k])
    assert ax.get_ylabel() == "drive effort (N m)" and ax.get_xlabel() == "speed (rad/s)"


def test_plot_results_four_panels_and_no_global_change(five_bar):
    _, res = five_bar
    before = dict(matplotlib.rcParams)
    fig = Figure()
    lines = plot_results(res, fig=fig)
    assert [a.get_title() for a in fig.axes[:4]] == ["coordinates", "rates", "drive efforts",
                                                     f"energy (balance drift {res.energy.drift:.2g} J)"]
    np.testing.assert_array_equal(lines[2].get_ydata(), res.qd[:, 0])
    assert dict(matplotlib.rcParams) == before


def test_frame_indices():
    t = np.linspace(0, 2, 201)  # every 10 ms
    idx = frame_indices(t, fps=10, speed=1.0)
    np.testing.assert_array_equal(idx, np.arange(0, 201, 10))  # a frame every 0.1 s
    assert len(frame_indices(t, fps=10)) == 31  # auto speed: 2 s of motion shown in 3 s
    assert len(frame_indices(t, fps=100, speed=0.01, max_frames=50)) == 50
    with pytest.raises(ValueError, match="positive"):
        frame_indices(t, fps=0)


def test_gif(slider_crank, tmp_path):
    mech, res = slider_crank
    path = pd.animate.animate(mech, res, tmp_path / "a.gif", fps=10, speed=0.1, size=(320, 240))
    with Image.open(path) as im:
        assert im.size == (320, 240)
        assert im.n_frames == 31  # 0.3 s at 0.1x, 10 frames/s
        assert im.info["duration"] == 100 and im.info["loop"] == 0
        first = np.asarray(im.convert("RGB"), dtype=float)
        im.seek(15)
        middle = np.asarray(im.convert("RGB"), dtype=float)
    assert first.std() > 10  # not blank
    assert np.abs(first - middle).mean() > 0.1  # the crank moved


def test_mp4(slider_crank, tmp_path):
    imageio_ffmpeg = pytest.importorskip("imageio_ffmpeg")
    mech, res = slider_crank
    path = pd.animate.animate(mech, res, tmp_path / "a.mp4", fps=10, speed=0.1, size=(320, 240))
    frames, secs = imageio_ffmpeg.count_frames_and_secs(str(path))
    assert frames == 31 and secs == pytest.approx(3.1, abs=0.11)
    with open(path, "rb") as f:
        assert f.read(12)[4:8] == b"ftyp"
    with pytest.raises(ValueError, match="multiples of 16"):
        pd.animate.animate(mech, res, tmp_path / "b.mp4", size=(300, 200))


def test_rendered_frame_shows_the_mechanism(slider_crank):
    # Frames are RGB arrays of the asked size with the coloured bars in them (pixels whose
    # red and blue differ a lot: the blue crank, the orange rod), and the crank turns.
    mech, res = slider_crank
    frames = list(render_frames(mech, res, fps=5, speed=0.1, size=(320, 240)))
    assert len(frames) == 16 and frames[0].shape == (240, 320, 3) and frames[0].dtype == np.uint8
    colored = lambda f: np.sum(np.abs(f[:, :, 0].astype(int) - f[:, :, 2].astype(int)) > 80)  # noqa: E731
    assert colored(frames[0]) > 100  # the coloured bars are there
    assert np.any(frames[0] != frames[-1])


def test_unknown_format(slider_crank, tmp_path):
    mech, res = slider_crank
    with pytest.raises(ValueError, match="unknown animation format '.avi'"):
        pd.animate.animate(mech, res, tmp_path / "a.avi")


# ---------------------------------------------------------------- issue 26, first hour 8


def crank_and_slider() -> pd.Mechanism:
    """Two coordinates of two kinds: a crank (an angle, rad, driven by N m) and a slider on its
    own ground guide (a displacement, m, N); the guide laid by the ground points G1 and G2."""
    return pd.from_dict({
        "name": "crank and slider", "points": {"O": [0, 0], "A": [0.1, 0], "B": [0.3, 0], "G1": [0.2, 0], "G2": [0.5, 0]},
        "ground": ["O", "G1", "G2"],
        "bodies": {"crank": {"points": ["O", "A"], "uniform_bar": ["O", "A"], "mass": 1.0},
                   "slider": {"points": ["B"], "mass": 2.0, "com": "B", "inertia": 1e-3}},
        "pairs": [{"type": "revolute", "name": "pivot", "at": "O", "bodies": ["ground", "crank"]},
                  {"type": "prismatic", "name": "guide", "at": "B", "bodies": ["ground", "slider"], "along": ["G1", "G2"]}],
        "coordinates": [{"name": "theta", "pair": "pivot", "value": 0.0, "qd0": 1.0},
                        {"name": "s", "pair": "guide", "value": 0.1, "qd0": 0.2}],
    })


def test_axis_labels_give_each_coordinates_unit():
    # Issue 26: the labels said "(rad or m)" and "(N m or N)" though the model knows them.
    mech = crank_and_slider()
    res = mech.simulate(t_end=0.1, output_dt=0.01)
    assert mech.coordinate_units == ["rad", "m"] and mech.effort_units == ["N m", "N"]
    ax = Figure().add_subplot()
    plot_coordinates(res, ax=ax)
    assert ax.get_ylabel() == "q: theta (rad), s (m)"
    plot_coordinates(res, ax=ax, which="qd")
    assert ax.get_ylabel() == "qd: qd_theta (rad/s), qd_s (m/s)"
    plot_efforts(res, ax=ax)
    assert ax.get_ylabel() == "drive effort: tau_theta (N m), tau_s (N)"
    plot_torque_speed(res, ax=ax)
    assert ax.get_xlabel() == "speed: theta (rad/s), s (m/s)"
    five = pd.load(MODELS / "five-bar.yaml").simulate(t_end=0.05)
    plot_coordinates(five, ax=ax, which="qdd")
    assert ax.get_ylabel() == "qdd (rad/s^2)"  # one unit: said once


def test_ground_points_laying_a_guide_are_not_drawn_as_pivots(slider_crank):
    # Issue 26: the ground's copy of the slider's point (the guide passes through it) and
    # G1, G2 (the guide's ends) had the hatched pivot mark; the crank's pivot and the spring's
    # anchor keep it.
    mech, _ = slider_crank
    assert mech.ground_points == ["O", "B", "W"] and pivot_points(mech) == ["O", "W"]
    assert pivot_points(crank_and_slider()) == ["O"]
    ax = Figure().add_subplot()
    artists = draw_mechanism(mech, ax=ax)
    hatched = [a for a in artists if isinstance(a, matplotlib.patches.Polygon) and a.get_hatch()]
    tips = [a.get_xy()[0] for a in hatched]  # each mark's tip is its point
    where = mech.point_positions(mech.x0)
    np.testing.assert_array_equal(tips, where[[mech.point_names.index("O"), mech.point_names.index("W")]])
    svg = pd.notebook.mechanism_svg(mech)
    assert svg.count("<polygon points=") - sum(len(b) >= 3 for b in mech.body_points) == 2


def test_point_paths_have_a_legend(five_bar):
    mech, res = five_bar
    ax = Figure().add_subplot()
    plot_point_paths(mech, res, ["P", "C1"], ax=ax)
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["path of P", "path of C1"]


def _display_points(line) -> np.ndarray:
    return line.get_transform().transform(np.column_stack(line.get_data()))


@pytest.mark.parametrize("model", ["five-bar.yaml", "four-bar-gravity.yaml"])
def test_energy_legend_covers_no_curve(model):
    # Issue 26: the legend sat on the balance curve (matplotlib's loc="best" avoids only the
    # lines of its own axes, and the balance is on the twin axes). No point of any curve of
    # either axes may fall inside the legend's box.
    res = pd.load(MODELS / model).simulate(t_end=0.5)
    fig = Figure(figsize=(11, 7))
    FigureCanvasAgg(fig)
    plot_results(res, fig=fig)
    fig.canvas.draw()
    energy = fig.axes[3]
    twin = [a for a in fig.axes[4:] if a.bbox.bounds == energy.bbox.bounds]
    box = energy.get_legend().get_window_extent()
    curves = energy.get_lines() + twin[0].get_lines()
    assert len(curves) == 5 and len(energy.get_legend().get_texts()) == 5
    def covered(line) -> bool:
        x, y = _display_points(line).T
        return bool(np.any((box.x0 <= x) & (x <= box.x1) & (box.y0 <= y) & (y <= box.y1)))

    inside = [ln.get_label() for ln in curves if covered(ln)]
    assert not inside, inside


def test_point_motion_plot_and_summary(slider_crank):
    # A point's position, velocity and acceleration against t (planardyn plot --points):
    # the crank pin A of the slider-crank, on a circle of radius 0.08 m about O.
    mech, res = slider_crank
    motion = mech.point_motion(res)
    fig = Figure()
    lines = plot_point_motion(motion, ["A"], fig=fig)
    assert [a.get_ylabel() for a in fig.axes] == ["position (m)", "velocity (m/s)", "acceleration (m/s^2)"]
    assert len(lines) == 6  # x and y of three quantities
    np.testing.assert_array_equal(lines[0].get_ydata(), motion["A"][0][:, 0])
    np.testing.assert_array_equal(lines[5].get_ydata(), motion["A"][2][:, 1])
    r = np.hypot(*motion["A"][0].T)
    np.testing.assert_allclose(r, 0.08, rtol=1e-12)  # the crank's length, from the model file
    text = motion.describe("A")
    lo, hi = motion["A"][0][:, 0].min(), motion["A"][0][:, 0].max()
    assert text.startswith(f"A: x {lo:.6g} .. {hi:.6g} m (travel {hi - lo:.4g} m)")
    with pytest.raises(ValueError, match="no point Z"):
        plot_point_motion(motion, ["Z"], fig=Figure())
