"""Every result object shows itself in a notebook (issue 26, first hour 5): a one-line
``__repr__`` without an array's contents, and a table (``_repr_html_``, or the formatter
planardyn.notebook registers) with the numbers a reader wants. Before, ``mech.point_motion(res)``,
a ``TimedPath`` and a sizing report printed about 200 lines of raw arrays."""

from __future__ import annotations

import dataclasses
import html
import json
import re
import types

import numpy as np
import planardyn as pdy
import pytest
from conftest import MODELS
from planardyn import notebook, robot
from planardyn.identify import Excitation, identify
from planardyn.results_io import attach_metadata
from planardyn.sensitivity import trajectory

#: A repr is one line, at most this long (a console's width, twice): no array's contents.
MAX_REPR = 240
#: A notebook table: enough for its rows, far from an array's thousands of numbers.
MAX_HTML = 6000


@pytest.fixture(scope="module")
def five_bar():
    return pdy.load(MODELS / "five-bar.yaml")


@pytest.fixture(scope="module")
def five_bar_5r():
    return pdy.load_example("library/five-bar-5r")


def check_repr(obj: object, *needles: str) -> str:
    text = repr(obj)
    assert "\n" not in text and len(text) <= MAX_REPR and "array(" not in text, text
    assert text.startswith(type(obj).__name__ + "("), text
    for needle in needles:
        assert needle in text, (needle, text)
    return text


def check_html(page: str, *needles: str) -> None:
    assert page.startswith("<div>") and len(page) <= MAX_HTML, len(page)
    for needle in needles:
        assert html.escape(needle) in page, (needle, page[:500])


def test_point_motion(five_bar):
    res = five_bar.simulate(t_end=0.2, output_dt=0.01)
    motion = five_bar.point_motion(res)
    check_repr(motion, "N=21", "t = 0..0.2 s", "points=(A1, A2, C1, C2, P)")
    page = notebook.point_motion_html(motion)
    check_html(page, "PointMotion", "21, t = 0 .. 0.2 s", motion.describe("P").removeprefix("P: "))

    class Shell:  # what register_display needs of IPython: its HTML formatter
        registered: dict[type, object] = {}

        class display_formatter:  # noqa: N801 - IPython's attribute
            formatters = {"text/html": type("F", (), {"for_type": lambda self, t, f: Shell.registered.update({t: f})})()}

    assert notebook.register_display(Shell())
    assert Shell.registered[pdy.PointMotion] is notebook.point_motion_html


def test_sizing_report_and_task_motion(five_bar):
    report = robot.size(robot.EndEffector(five_bar, "P"), robot.circle((0.014, 0.5097), 0.06, duration=1.0))
    d = report.drives[0]
    check_repr(report, "five-bar 5R robot, driven on circle", f"theta1 {d.peak_effort:.4g} N m",
               f"min sigma_II {report.min_sigma_II[0]:.3g}")
    check_repr(d, f"peak {d.peak_effort:.4g} N m", f"RMS {d.rms_effort:.4g} N m")
    check_html(report._repr_html_(), "SizingReport", "peak effort", f"{d.rms_effort:.4g} N m",
               f"{d.peak_power:.4g} W", "nearest type II singularity")
    check_repr(report.motion, "1001 samples")
    check_html(report.motion._repr_html_(), "TaskMotion", "1001, t = 0 .. 1 s", "min sigma_I, sigma_II")


def test_sizing_report_with_motors_lists_the_checks():
    from test_actuators import five_bar_with_motors, sized

    limits = {"theta1": {"peak_torque": 1.0}, "theta2": {"peak_torque": 1.0}}  # N m, motor side
    report = sized(five_bar_with_motors(limits))
    motor = next(d.motor for d in report.drives if d.motor is not None)
    check_repr(motor, motor.name, "limits)")
    page = report._repr_html_()
    check_html(page, "margin", motor.checks[0].quantity, f"{100 * motor.checks[0].margin:.2f} %")


def test_planned_motions(five_bar_5r):
    from planardyn.plan import collocate, task_waypoints, time_optimal

    ee = robot.EndEffector(five_bar_5r, "P")
    timed = time_optimal(five_bar_5r, task_waypoints(ee, [(-0.08, 0.28), (0.08, 0.36)], 0.01), [3, 3])
    check_repr(timed, f"{timed.duration:.6g} s", "grid points")
    check_html(timed._repr_html_(), "TimedPath", f"{timed.duration:.6g} s", "peak |tau|",
               f"{np.abs(timed.tau[:, 0]).max():.4g} N m", "rad/s")
    start, end = ee.inverse((-0.08, 0.28)), ee.inverse((0.08, 0.36))
    moved = collocate(five_bar_5r, start.q, end.q, objective="time", effort=[3, 3], n_intervals=10)
    check_repr(moved, "10 intervals", "IPOPT")
    check_html(moved._repr_html_(), "CollocatedMotion", "minimum time")


def test_identification_and_base_parameters(five_bar):
    res = five_bar.simulate(t_end=0.5, output_dt=0.002)
    found = identify(five_bar, res.q, res.qd, res.qdd, res.tau, x=res.x)
    check_repr(found, f"{found.base.rank} base parameters from {found.samples} samples")
    check_repr(found.base, f"{found.base.rank} of {len(found.base.parameters)} parameters identifiable")
    check_html(found._repr_html_(), "Identification", "base parameter", "std error", found.base.expressions[0][:40])
    ex = Excitation(q0=five_bar.q0, period=1.0, a=np.zeros((2, 3)), b=np.zeros((2, 3)), condition=12.5,
                    start_condition=80.0)
    check_repr(ex, "period 1 s, 3 harmonics on 2 coordinates", "condition 12.5")


def test_sensitivity(five_bar):
    sens = trajectory(five_bar, ["bodies.proximal_left.mass"], np.linspace(0, 0.1, 101), threads=1)
    check_repr(sens, "bodies.proximal_left.mass", "[101, 2]")
    check_html(sens._repr_html_(), "Sensitivity", "bodies.proximal_left.mass", "derivative (largest entry)")


def test_maps(five_bar):
    ee = robot.EndEffector(five_bar, "P")
    grid = robot.singularity_map(ee, (-0.1, 0.1), (0.4, 0.55), n=12)
    check_repr(grid, "12 x 12 cells", "reachable")
    cmap = robot.capability_map(ee, (-0.05, 0.05), (0.45, 0.52), n=6, tau_max=[5, 5])
    text = check_repr(cmap, "6 x 6 cells", "m/s^2")
    assert re.search(r"\|tau\| <= \[5\.0, 5\.0\]", text)


# ------------------------------------------------------------------ the app in a notebook


@pytest.fixture
def fresh_session(monkeypatch):
    """A notebook session whose page holds no engine yet."""
    monkeypatch.setattr(notebook, "_engine_shown", False)


def test_mechanism_summary_svg(five_bar):
    svg = notebook.mechanism_svg(five_bar)
    assert svg.startswith("<svg") and svg.endswith("</svg>")
    assert svg.count("<polyline") == five_bar.n_bodies  # four bars
    assert svg.count("<circle") == len(five_bar.pairs)
    assert all(f">{n}</text>" in svg for n in five_bar.point_names)
    page = notebook.mechanism_summary(five_bar)
    assert "five-bar 5R robot, driven" in page and "theta1 = 2.00713 rad" in page
    assert "2 (3n - 2p = 2)" in page


def test_result_summary(five_bar):
    res = five_bar.simulate()
    # Without its model (simulate attaches it): the summary alone, no app.
    plain = notebook.result_html(dataclasses.replace(res, metadata={}))
    assert "success" in plain and "301" in plain and "<svg" not in plain and "<iframe" not in plain
    assert "tau 2.41 .. 2.41" not in plain and "tau -2.41 .. -2.41 N m" in plain
    rich = notebook.result_summary(attach_metadata(res, five_bar, {}))
    assert "<svg" in rich and rich.count("<polyline") == five_bar.n_bodies + 3  # bars and 3 paths
    with pytest.raises(ValueError, match="does not carry its model"):
        notebook.app_view(dataclasses.replace(res, metadata={}))


def app_data(page: str) -> dict:
    found = re.findall(r'<script type="application/json" id="planardyn-[0-9a-f]+-data">(.*?)</script>', page, re.S)
    assert len(found) == 1
    return json.loads(found[0])


def test_displays_are_the_app_with_the_engine_once(five_bar, fresh_session):
    # The first display holds the engine (the app's page, gzipped and base64-encoded: about
    # 1.3 MB); the next ones only their model (a few kB) or their run.
    first, second = notebook.mechanism_html(five_bar), notebook.mechanism_html(five_bar)
    assert first.count("window.planardynApp=(async") == 1 and "window.planardynApp=(async" not in second
    assert len(second) < 20_000 < 1_000_000 < len(first)
    model = app_data(second)["model"]
    assert pdy.loads(model["text"]) == five_bar and model["format"] == "yaml"
    res = five_bar.simulate(t_end=0.5, output_dt=0.01)
    run = app_data(notebook.result_html(res))["run"]
    np.testing.assert_allclose(np.reshape(run["P"], (51, -1, 2)), five_bar.point_positions(res.x), rtol=0,
                               atol=1e-6 * five_bar.scale)  # rounded to 6 digits of L (replay.DIGITS)
    # engine() puts it back in a later cell (its first output cleared); save() writes the app.
    assert "window.planardynApp=(async" in notebook.engine()._repr_html_()


def test_app_view_saves_the_offline_app(five_bar, fresh_session, tmp_path):
    view = notebook.app_view(five_bar, five_bar.simulate(t_end=0.2, output_dt=0.05))
    view.save(tmp_path / "app.html")
    page = (tmp_path / "app.html").read_text()
    data = json.loads(re.search(r'id="planardyn-data">(.*?)</script>', page, re.S).group(1))
    assert data["run"]["t"] == pytest.approx([0.0, 0.05, 0.1, 0.15, 0.2])


def notebook_size(cells: list[str]) -> int:
    """Bytes of an .ipynb (nbformat 4, as Jupyter writes it: indent 1) whose code cells have
    these HTML outputs."""
    nb = {"nbformat": 4, "nbformat_minor": 5, "metadata": {}, "cells": [
        {"cell_type": "code", "execution_count": k + 1, "id": f"c{k}", "metadata": {}, "source": ["m"],
         "outputs": [{"output_type": "execute_result", "execution_count": k + 1, "metadata": {},
                      "data": {"text/html": html_text.splitlines(keepends=True), "text/plain": ["<Mechanism>"]}}]}
        for k, html_text in enumerate(cells)]}
    return len(json.dumps(nb, indent=1, ensure_ascii=False).encode("utf-8"))


def test_a_notebook_with_five_apps_stays_light(five_bar, monkeypatch):
    # Five displays of the mechanism weigh the engine once and five models: the notebook of
    # five is less than 4 % larger than the notebook of one (measured: 1.35 MB and 1.38 MB).
    sizes = {}
    for n in (1, 5):
        monkeypatch.setattr(notebook, "_engine_shown", False)
        sizes[n] = notebook_size([notebook.mechanism_html(five_bar) for _ in range(n)])
    assert sizes[5] < 1.04 * sizes[1]


def test_register_display_hands_the_views_to_ipython(five_bar, fresh_session):
    # A stand-in for IPython's shell: display_formatter.formatters["text/html"].for_type(cls, f).
    printers = {}

    class Formatter:
        def for_type(self, cls, printer):
            printers[cls] = printer

    shell = types.SimpleNamespace(display_formatter=types.SimpleNamespace(formatters={"text/html": Formatter()}))
    assert notebook.register_display(shell)
    assert printers == {pdy.Mechanism: notebook.mechanism_html, pdy.SimulationResult: notebook.result_html,
                        pdy.PointMotion: notebook.point_motion_html}
    assert "planardyn-summary" in printers[type(five_bar)](five_bar)
    assert notebook.register_display() is False  # no running IPython shell under pytest: nothing to do
