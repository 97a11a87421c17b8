"""Every result object shows itself in a notebook (issue 26, first hour 5): a one-line
``__repr__`` without an array's contents, and a table (``_repr_html_``, or the formatter
planardyn.notebook registers) with the numbers a reader wants. Before, ``mech.point_motion(res)``,
a ``TimedPath`` and a sizing report printed about 200 lines of raw arrays."""

from __future__ import annotations

import html
import re

import numpy as np
import planardyn as pdy
import pytest
from conftest import MODELS
from planardyn import notebook, robot
from planardyn.identify import Excitation, identify
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
