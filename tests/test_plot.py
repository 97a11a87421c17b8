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
from matplotlib.figure import Figure
from PIL import Image
from planardyn.animate import frame_indices, render_frames
from planardyn.plot import (
    default_trace_points,
    draw_mechanism_at,
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
