"""What planardyn does, in one folder, in about half a minute: ``planardyn demo`` and ``./dev demo``.

Two shipped models, nothing from the repository:

- the 5R robot (``five-bar``) with 0.5 kg at its end effector P tracing a circle: inverse
  kinematics and dynamics along the path, the drive torques, the actuator sizing report, its
  singularity map, and a forward simulation under those torques (the check that they produce
  the motion) in the browser app;
- a passive mechanism (``four-bar-gravity``: the crank swings from +60 deg to about -233 deg
  under gravity) simulated, plotted, animated (GIF) and in the browser app.

    from planardyn.demo import run
    demo = run("out/demo", echo=print)    # one line per file: its path, what it is
    demo.files, demo.success
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from . import robot
from .animate import animate
from .mechanism import Mechanism, load, load_example
from .plot import draw_mechanism, plot_results
from .result import SimulationResult
from .results_io import attach_metadata, simulate_settings, write_results

#: The robot: a shipped model, its end-effector point, the payload (kg) carried there.
ROBOT_MODEL, ROBOT_POINT, PAYLOAD = "five-bar", "P", 0.5
#: The task: a circle of this radius (m) above the drawn P, in this time (s), rest to rest.
RADIUS, DURATION, DT = 0.06, 1.0, 2e-3
#: The singularity map's region (m) and grid points per side.
MAP_X, MAP_Y, MAP_N = (-0.45, 0.45), (-0.1, 0.65), 40
#: The passive mechanism and how long it is simulated (s; a model given by the user runs for
#: its file's t_end, else 1 s).
PASSIVE_MODEL, PASSIVE_T_END, OUTPUT_DT = "four-bar-gravity", 4.0, 0.01
#: Snapshots of the passive mechanism on one figure, from its start to its farthest excursion.
SNAPSHOTS = 4

Written = list[tuple[Path, str]]


class Demo(NamedTuple):
    """What :func:`run` wrote: (path, what it is) for every file; ``success``: every
    simulation reached its end time."""

    files: Written
    success: bool


def _figure(size: tuple[float, float]) -> Figure:
    fig = Figure(figsize=size)
    FigureCanvasAgg(fig)
    return fig


def _save(fig: Figure, path: Path) -> Path:
    fig.savefig(path, dpi=110)
    return path


def robot_outputs(out: Path) -> tuple[Written, bool]:
    """The 5R robot on its circle: motion, sizing, singularity map, the app; and whether the
    open-loop check ran to its end."""
    ee = robot.EndEffector(load_example(ROBOT_MODEL), ROBOT_POINT)
    path = robot.circle(center=ee.home() + [0.0, RADIUS], radius=RADIUS, duration=DURATION)
    report = robot.size(ee, path, payload=PAYLOAD, dt=DT)
    motion = report.motion
    written: Written = []

    fig = _figure((11, 7))
    robot.plot_motion(motion, fig=fig)
    peaks = ", ".join(f"{d.name} {d.peak_effort:.3g} {d.effort_unit}" for d in report.drives)
    written.append((_save(fig, out / "robot-motion.png"),
                    f"the 5R robot tracing a {RADIUS:g} m circle in {DURATION:g} s: path, inputs, drive torques "
                    f"(peaks {peaks}), distance to singularities"))

    (out / "robot-sizing.txt").write_text(str(report) + "\n")
    written.append((out / "robot-sizing.txt", "its actuator sizing report: peak and RMS torque, speed, power per drive"))
    fig = _figure((11, 7))
    robot.plot_sizing(report, fig=fig)
    written.append((_save(fig, out / "robot-sizing.png"),
                    "the sizing as plots: torques with RMS, torque-speed envelope, mechanical power"))

    grid = robot.singularity_map(ee, MAP_X, MAP_Y, n=MAP_N)
    fig = _figure((11, 5))
    robot.plot_singularity_map(grid, fig=fig)
    written.append((_save(fig, out / "singularity-map.png"),
                    f"where the robot can go: type I and II singularity measures over {grid.area:.3g} m^2 "
                    "of reachable end-effector positions"))

    res = motion.simulate()
    err = float(np.abs(motion.task_of(res.q) - motion.X).max())
    animate(motion.mech, res, out / "robot.html", traces=[ROBOT_POINT])
    written.append((out / "robot.html",
                    f"the browser app: the robot driven by those torques alone (open loop) retraces the circle to {err:.1g} m; "
                    "open it in a browser"))
    return written, res.success


def passive_outputs(out: Path, model: str | os.PathLike[str] | None = None) -> tuple[Written, bool]:
    """A passive mechanism moving under its loads: results, plots, snapshots, GIF, the app;
    and whether its simulation reached its end time."""
    mech = load_example(PASSIVE_MODEL) if model is None else load(model)
    settings = simulate_settings(mech, t_end=PASSIVE_T_END if model is None else None, output_dt=OUTPUT_DT)
    res = attach_metadata(mech.simulate(**settings), mech, settings)
    written: Written = []

    write_results(res, out / "passive.csv")
    q = ", ".join(f"{n} {lo:.3g}..{hi:.3g}" for n, lo, hi in zip(mech.coordinate_names, res.q.min(0), res.q.max(0)))
    written.append((out / "passive.csv",
                    f"{mech.name}: {res.status} to t = {res.t[-1]:.3g} s, {q} "
                    f"(results file, its metadata in passive.csv.json: planardyn plot / animate read it)"))

    fig = _figure((11, 7))
    plot_results(res, fig=fig)
    exchanged = float(np.ptp(res.energy.kinetic)) if len(res.t) else 0.0
    written.append((_save(fig, out / "passive.png"),
                    f"its coordinates, rates, efforts and energy: {exchanged:.3g} J exchanged between kinetic and "
                    f"potential, balance within {res.energy.drift:.2g} J"))

    fig = _figure((4 * SNAPSHOTS, 4))
    _snapshots(mech, res, fig)
    written.append((_save(fig, out / "passive-snapshots.png"), f"the mechanism at {SNAPSHOTS} instants"))

    animate(mech, res, out / "passive.gif")
    written.append((out / "passive.gif", "its animation (GIF)"))
    animate(mech, res, out / "passive.html")
    written.append((out / "passive.html", "the browser app with the run: play, scrub, chart, or drag and edit the model; open it in a browser"))
    return written, res.success


def _snapshots(mech: Mechanism, res: SimulationResult, fig: Figure) -> None:
    # From the start to the farthest excursion of the coordinates: the whole swing, once.
    dist = np.abs(res.q - res.q[0]).sum(axis=1)
    far = int(np.argmax(dist >= 0.99 * dist.max()))
    idx = np.linspace(0, far or len(res.t) - 1, SNAPSHOTS).round().astype(int)
    pts = mech.point_positions(res.x)  # (N, P, 2)
    lo, hi = np.nanmin(pts, axis=(0, 1)), np.nanmax(pts, axis=(0, 1))
    pad = 0.1 * mech.scale
    for ax, k in zip(np.atleast_1d(fig.subplots(1, SNAPSHOTS)), idx):
        draw_mechanism(mech, res.x[k], ax=ax, labels=True)
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_title(f"t = {res.t[k]:.3g} s")
    fig.tight_layout()


def run(out: str | os.PathLike[str], model: str | os.PathLike[str] | None = None,
        echo: Callable[[str], Any] | None = None) -> Demo:
    """Write the demo into folder ``out``; ``model``: a model file for the passive part
    (default the shipped four-bar under gravity). ``echo(line)`` is called with one line per
    file, path then what it is, as each part is done."""
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    files: Written = []
    success = True
    for part in (lambda: robot_outputs(folder), lambda: passive_outputs(folder, model)):
        written, ok = part()
        for path, what in written:
            if echo is not None:
                echo(f"{path}  {what}")
        files += written
        success = success and ok
    return Demo(files, success)
