"""The HTML viewer in a real headless browser (Debian's chromium, which ./dev installs), and
the notebook views.

The page reports its state in the DOM (``<body data-frame data-drawn data-ready>`` and the
title), so ``--dump-dom`` after some virtual time shows whether the animation advanced;
``--enable-logging=stderr`` shows the page's console messages, which must be none. A
screenshot must show the mechanism (pixels of the bodies' colours in the drawing area).
"""

from __future__ import annotations

import dataclasses
import json
import re
import shutil
import subprocess
import time
import types

import numpy as np
import planardyn as pd
import pytest
from conftest import MODELS
from PIL import Image
from planardyn.notebook import mechanism_html, mechanism_svg, point_motion_html, register_display, result_html, viewer
from planardyn.results_io import attach_metadata
from planardyn.viewer import DIGITS, viewer_data, viewer_html, write_viewer

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
needs_browser = pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (./dev installs it as root)")
# The five-bar run: 1.5 s every 5 ms (301 outputs), shown by default at 0.5x (in 3 s).
DT = 0.005
AUTO_SPEED = 0.5


@pytest.fixture(scope="module")
def five_bar():
    mech = pd.load(MODELS / "five-bar.yaml")
    res = mech.simulate()
    assert len(res.t) == 301 and res.t[-1] == 1.5
    return mech, res


def chromium(tmp_path, url: str, *args: str, budget_ms: int = 1000) -> subprocess.CompletedProcess:
    cmd = [
        CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        "--disable-default-apps", "--mute-audio", f"--user-data-dir={tmp_path / 'profile'}",
        "--enable-logging=stderr", "--v=0", f"--virtual-time-budget={budget_ms}", "--window-size=1200,800",
        *args, url,
    ]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=90)


def console_messages(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if ":CONSOLE" in line]


def body_attrs(dom: str) -> dict[str, str]:
    tag = re.search(r"<body([^>]*)>", dom).group(1)
    return dict(re.findall(r'([\w-]+)="([^"]*)"', tag))


@needs_browser
def test_viewer_plays_in_a_browser(five_bar, tmp_path):
    mech, res = five_bar
    page = write_viewer(mech, res, tmp_path / "viewer.html")
    start = time.monotonic()
    p = chromium(tmp_path, page.as_uri(), "--dump-dom", budget_ms=1000)
    elapsed = time.monotonic() - start
    assert p.returncode == 0, p.stderr[-2000:]
    assert console_messages(p.stderr) == []
    attrs = body_attrs(p.stdout)
    assert attrs["data-ready"] == "1" and "data-error" not in attrs
    frame, drawn = int(attrs["data-frame"]), int(attrs["data-drawn"])
    # 1 s of (virtual) playback at 0.5x is 0.5 s of motion: frame 100 at most. How much of
    # the budget the page load takes depends on the machine's load (seen: frame 99 idle,
    # under 40 on a loaded CI machine), so the lower bound only says that it advanced.
    assert 1 <= frame <= round(1.0 * AUTO_SPEED / DT) + 1, frame
    assert drawn >= 1
    assert re.search(rf"<title>{re.escape(mech.name)} \| frame {frame}/300</title>", p.stdout)
    assert elapsed < 60


@needs_browser
def test_viewer_seeks_from_the_address_and_shows_the_mechanism(five_bar, tmp_path):
    mech, res = five_bar
    page = write_viewer(mech, res, tmp_path / "viewer.html")
    p = chromium(tmp_path, page.as_uri() + "#t=1.0&paused", "--dump-dom", budget_ms=500)
    assert console_messages(p.stderr) == []
    assert body_attrs(p.stdout)["data-frame"] == "200"  # t = 1.0 s, paused there
    assert 't = 1.000 s' in p.stdout
    shot = tmp_path / "viewer.png"
    p = chromium(tmp_path, page.as_uri() + "#t=1.0&paused", f"--screenshot={shot}", budget_ms=500)
    assert p.returncode == 0 and shot.is_file(), p.stderr[-2000:]
    img = np.asarray(Image.open(shot).convert("RGB"), dtype=int)
    assert img.shape == (800, 1200, 3)
    assert img.std() > 20  # not blank
    # The left distal link is drawn in matplotlib's C2 green (#2ca02c), the plots' curves too:
    # count the green pixels in the mechanism's canvas (left half) and in the plots (right).
    green = (np.abs(img - [0x2C, 0xA0, 0x2C]).sum(axis=2) < 60)
    assert green[:, :600].sum() > 300
    blue = (np.abs(img - [0x1F, 0x77, 0xB4]).sum(axis=2) < 60)  # proximal left link, theta1 curve
    assert blue[:, :600].sum() > 200 and blue[:, 600:].sum() > 100


@needs_browser
def test_console_errors_are_caught(five_bar, tmp_path):
    # The detector works: the same page with a script error reports it on the console.
    mech, res = five_bar
    page = tmp_path / "broken.html"
    page.write_text(viewer_html(mech, res).replace("buildPlots();\n  if", "notAFunction();\n  if"))
    p = chromium(tmp_path, page.as_uri(), "--dump-dom", budget_ms=300)
    msgs = console_messages(p.stderr)
    assert any("notAFunction is not defined" in m for m in msgs), p.stderr[-2000:]
    assert body_attrs(p.stdout)["data-ready"] == "0"


def test_viewer_is_self_contained(five_bar):
    mech, res = five_bar
    page = viewer_html(mech, res, channels=["theta2", "kinetic"])
    assert "http://" not in page.replace("http://www.w3.org", "") and "https://" not in page
    assert "<script src" not in page and "<link" not in page
    data = json.loads(re.search(r'<script id="planardyn-data" type="application/json">(.*?)</script>', page, re.S).group(1))
    assert data["names"] == mech.point_names and len(data["t"]) == 301
    on = [c["key"] for c in data["channels"] if c["on"]]
    assert on == ["theta2", "kinetic"]
    # Positions rounded to 6 significant digits of the mechanism's size.
    P = np.array(data["P"]).reshape(301, -1, 2)
    np.testing.assert_allclose(P, mech.point_positions(res.x), rtol=0, atol=1e-6 * mech.scale)
    tau = next(c for c in data["channels"] if c["key"] == "tau_theta2")
    np.testing.assert_allclose(tau["values"], res.tau[:, 1], rtol=1e-5)
    with pytest.raises(ValueError, match="unknown channel"):
        viewer_html(mech, res, channels=["nope"])


def test_viewer_subsamples_long_results(five_bar):
    mech, res = five_bar
    data = viewer_data(mech, res, max_frames=51)
    assert len(data["t"]) == 51 and data["t"][0] == 0.0 and data["t"][-1] == 1.5
    assert data["speed"] == pytest.approx(AUTO_SPEED)


def test_prismatic_guide_in_data():
    mech = pd.load(MODELS / "slider-crank.yaml")
    res = mech.simulate(t_end=0.1, output_dt=0.01)
    data = viewer_data(mech, res)
    guides = [j for j in data["joints"] if j["kind"] == "prismatic"]
    assert len(guides) == 1 and len(guides[0]["lines"]) == 11
    # The guide is drawn +-0.3 L about the block, along the horizontal axis of the model;
    # positions are rounded to 6 digits of L (1e-6 L).
    lines, blocks = np.array(guides[0]["lines"]), np.array(guides[0]["blocks"])
    L = data["scale"]
    np.testing.assert_allclose(np.hypot(lines[:, 2] - lines[:, 0], lines[:, 3] - lines[:, 1]) / L, 0.6, atol=3e-6)
    np.testing.assert_allclose(lines[:, 1], lines[:, 3], atol=1e-6 * L)
    np.testing.assert_allclose((lines[:, :2] + lines[:, 2:]) / 2, blocks, atol=1e-6 * L)


# ------------------------------------------------------------------ notebook


def test_mechanism_svg_and_html(five_bar):
    mech, _ = five_bar
    svg = mechanism_svg(mech)
    assert svg.startswith("<svg") and svg.endswith("</svg>")
    assert svg.count("<polyline") == mech.n_bodies  # four bars
    assert svg.count("<circle") == len(mech.pairs)
    assert all(f">{n}</text>" in svg for n in mech.point_names)
    html = mech_html = mechanism_html(mech)
    assert "five-bar 5R robot, driven" in mech_html and "theta1 = 2.00713 rad" in html
    assert "2 (3n - 2p = 2)" in html


def test_result_html(five_bar):
    mech, res = five_bar
    # Without its model (simulate attaches it): the summary alone.
    plain = result_html(dataclasses.replace(res, metadata={}))
    assert "success" in plain and "301" in plain and "<svg" not in plain
    assert "tau 2.41 .. 2.41" not in plain and "tau -2.41 .. -2.41 N m" in plain
    with_model = attach_metadata(res, mech, {})
    rich = result_html(with_model)
    assert "<svg" in rich and rich.count("<polyline") == mech.n_bodies + 3  # bars and 3 paths
    v = viewer(None, with_model)
    frame = v._repr_html_()
    assert frame.startswith("<iframe srcdoc=") and "&lt;canvas" in frame
    with pytest.raises(ValueError, match="does not carry its model"):
        viewer(None, dataclasses.replace(res, metadata={}))


def test_register_display_hands_both_views_to_ipython(five_bar):
    # A stand-in for IPython's shell: display_formatter.formatters["text/html"].for_type(cls, f).
    mech, res = five_bar
    printers = {}

    class Formatter:
        def for_type(self, cls, printer):
            printers[cls] = printer

    shell = types.SimpleNamespace(display_formatter=types.SimpleNamespace(formatters={"text/html": Formatter()}))
    assert register_display(shell)
    assert printers == {pd.Mechanism: mechanism_html, pd.SimulationResult: result_html,
                        pd.PointMotion: point_motion_html}
    assert printers[type(mech)](mech).startswith('<div style="display:flex')
    assert register_display() is False  # no running IPython shell under pytest: nothing to do


def test_viewer_has_pair_forces_and_point_motion_channels(five_bar):
    # Each pair's force magnitude and each traced point's speed and acceleration, computed
    # along the frames kept (each on its own branch): the values are those of
    # mech.reactions(res) and mech.point_motion(res), rounded to the page's DIGITS (6)
    # significant digits of each channel's largest value: within half a unit of that digit.
    mech, res = five_bar
    data = viewer_data(mech, res, channels=["F_elbow1", "v_P"])
    chans = {c["key"]: c for c in data["channels"]}
    assert {g["key"] for g in data["groups"]} >= {"reactions", "speeds", "point_accelerations"}
    assert {f"F_{p}" for p in mech.pair_names} | {"v_P", "a_P"} <= set(chans)
    assert chans["F_elbow1"]["on"] and chans["v_P"]["on"] and not chans["a_P"]["on"]
    f = mech.reactions(res)[:, mech.pair_names.index("elbow1"), :2]
    def half_unit(v):
        return 0.5 * 10.0 ** (np.floor(np.log10(v.max())) - (DIGITS - 1))

    force = np.hypot(*f.T)
    np.testing.assert_allclose(chans["F_elbow1"]["values"], force, rtol=0, atol=half_unit(force))
    v = mech.point_motion(res)["P"][1]
    speed = np.hypot(*v.T)
    np.testing.assert_allclose(chans["v_P"]["values"], speed, rtol=0, atol=half_unit(speed))
