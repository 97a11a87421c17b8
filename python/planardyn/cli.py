"""The ``planardyn`` command: a thin wrapper over the Python API.

    planardyn check MODEL
    planardyn simulate MODEL [--t-end T] [--method M] [--rtol R] [--atol A] [--dt H]
                             [--output-dt H] [--max-steps N] [-o results.csv|.parquet|.npz]
    planardyn inverse MODEL --motion FILE [-o results.csv|.parquet|.npz]
    planardyn identify MODEL DATA [--cutoff HZ] [--validate DATA] [-o FILE.json]
    planardyn plot RESULTS [-o FILE.png] [--torque-speed | --points P [P ...]]
    planardyn animate [MODEL] RESULTS -o FILE.gif|FILE.mp4|FILE.html
    planardyn size MODEL (--circle CX CY R | --line X0 Y0 X1 Y1) [--payload KG] ...
    planardyn stiffness MODEL --body B [--point P] [--at Q ...] [--load FX FY M] [--map X0 X1 Y0 Y1]
    planardyn modes MODEL [--at Q ...] [--free-rotors | --passive] [--gravity]
    planardyn flexible MODEL [--t-end T] [--output-dt H] [-o FILE.csv]
    planardyn plan MODEL --line X0 Y0 X1 Y1 (--effort T [T ...] | --actuators) [--speed V ...] [--collocate time|effort] [-o FILE.csv]
    planardyn demo [--out DIR] [--model MODEL]
    planardyn export MODEL -o FILE.xml|.urdf|.sdf;  planardyn import FILE -o MODEL.yaml
    planardyn docs [PAGE]
    planardyn --version

MODEL is a model file, or a shipped model by name (``five-bar``: planardyn.models.resolve).

Exit status: 0 success; 1 the computation failed (the simulation stopped before t_end: the
results file still holds the trajectory computed; the start could not be assembled); 2 a
usage, file or model error. Errors are one message on stderr, never a traceback.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import importlib
import json
import os
import sys
import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any, TextIO

from . import (
    ArgumentError,
    AssemblyError,
    DataError,
    Mechanism,
    PlanardynError,
    SimulationError,
    SingularityError,
    __version__,
    dimensions,
    drawing,
    extras,
    from_result,
    guide,
    load,
    models,
    structure,
)
from .events import Crossing, parse_crossing
from .exchange.cli import register as exchange_commands
from .guard import RunGuard, available_memory, rows_message
from .result import SimulationResult
from .results_format import check_writable, writing
from .robot.cli import register as size_command
from .robot.cli_options import number
from .settings import check_settings
from .stiffness_cli import register as stiffness_commands

EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2

RESULT_EXTENSIONS = (".csv", ".parquet", ".npz")


class UsageError(Exception):
    """A command line that cannot be carried out as given (exit 2)."""


#: What writing a file of this extension needs beyond the dependencies: (extra, what it writes).
OPTIONAL_WRITERS = {".parquet": ("parquet", "a .parquet file"), ".mp4": ("mp4", "an .mp4 file"),
                    ".dxf": ("cad", "a .dxf drawing")}
#: Integration methods without error control, whose step must be given (--dt).
FIXED_STEP_METHODS = ("rk4",)


def require_writer(path: Path | None) -> None:
    """Refuse, before any computation, an output file that cannot be written (its directory
    made, the cause in words) or whose optional package is missing."""
    if path is None:
        return
    check_writable(path)
    if path.suffix.lower() not in OPTIONAL_WRITERS:
        return
    extra, what = OPTIONAL_WRITERS[path.suffix.lower()]
    for module in extras.MODULES[extra]:
        try:
            importlib.import_module(module)
        except ImportError as e:
            raise UsageError(f"{path}: {extras.missing(extra, what, e)}") from None


def _warning_line(message: Warning | str, category: type[Warning], *_: Any, **__: Any) -> None:
    """warnings.showwarning for the command: one line, no source line or file position."""
    print(f"planardyn: warning: {' '.join(str(message).split())}", file=sys.stderr)


class ProgressBar:
    """A progress bar on a stream (tqdm's: percentage, elapsed time, time left), moved to a
    position: ``bar(t)`` for a run's time t from 0 to ``total`` s, ``bar(done)`` of ``total``
    frames. The end is drawn once, by :meth:`close` (tqdm would draw it again there)."""

    def __init__(self, total: float, unit: str = "s", stream: TextIO | None = None) -> None:
        from tqdm import tqdm

        self.total, self.position = float(total), 0.0
        self.bar = tqdm(total=self.total, file=sys.stderr if stream is None else stream, leave=True,
                        bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} " + unit + " [{elapsed}<{remaining}]")

    def __call__(self, position: float) -> None:
        self.position = min(max(float(position), self.position), self.total)
        if self.position < self.total:
            self.bar.update(self.position - self.bar.n)

    def close(self) -> None:
        self.bar.n = self.position
        self.bar.close()


def _crossing(text: str) -> Crossing:
    """``--stop-when``'s argument (argparse reports a ValueError as a usage error)."""
    try:
        return parse_crossing(text)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def summary(res: SimulationResult) -> str:
    """One line: status, outputs, steps, energy balance drift, smallest singularity measure."""
    st = res.stats
    if not len(res.t):
        # Nothing ran: no time, balance or measure to report (the message says why).
        return f"{res.status}: no outputs, the run stopped at its start before its first row"
    min_sigma = st.get("min_sigma")
    sigma_text = "-" if min_sigma is None else f"{min_sigma:.3g}"
    return (
        f"{res.status}: {len(res.t)} outputs to t = {res.t[-1]:.6g} s, {st.get('naccept', 0)} steps "
        f"({st.get('nreject', 0)} rejected, {st.get('nfev', 0)} evaluations), "
        f"energy drift {res.energy.drift:.3g} J, min sigma {sigma_text}"
        + "".join(f"; change point at t = {c.t:.6g} s (rank -{c.rank_drop})" for c in res.change_points)
    )


# ------------------------------------------------------------------ the parser

MODEL_HELP = "model file (.yaml, .yml or .json), or a shipped model by name (five-bar; see planardyn.models.names())"
EPILOG = "Exit status: 0 ok, 1 the computation failed, 2 usage or model error."
PLAN_HELP = "time-optimal timing of an end-effector line, or the optimal motion between its ends (the 'plan' extra)"


def _sub(sub, name: str, help: str, description: str, examples: str) -> argparse.ArgumentParser:
    return sub.add_parser(
        name,
        help=help,
        description=description,
        epilog="examples:\n" + examples.rstrip() + "\n\n" + EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )


def _results_path(value: str) -> Path:
    p = Path(value)
    if p.suffix.lower() not in RESULT_EXTENSIONS:
        raise argparse.ArgumentTypeError(
            f"{value}: results files end in {', '.join(RESULT_EXTENSIONS)}"
        )
    return p


def _setting(name: str) -> Callable[[str], float | int]:
    """An argparse type for the simulation setting ``name``, by its rule in planardyn.settings."""

    def parse(text: str) -> float | int:
        try:
            value: float | int = int(text) if name == "max_steps" else float(text)
        except ValueError:
            kind = "an integer" if name == "max_steps" else "a number"
            raise argparse.ArgumentTypeError(f"{text!r} is not {kind}") from None
        try:
            return check_settings(**{name: value})[name]
        except (ValueError, TypeError, SimulationError) as e:
            raise argparse.ArgumentTypeError(str(e).removeprefix("invalid option: ")) from None

    return parse


#: A frame rate or a playback speed given as 0 < value <= this is taken; beyond, refused.
MAX_FPS = 240.0
#: Resolution of plot images (dots per inch): 600 makes an 11 x 7 in figure about 100 MB.
DPI_RANGE = (10.0, 600.0)


def _parser(command: str | None = None) -> argparse.ArgumentParser:
    """The command's parser. ``command``: the one to be run, whose own parser is built in
    full (``plan``'s imports toppra and casadi, a second and more: built only when it runs)."""
    p = argparse.ArgumentParser(
        prog="planardyn",
        description="Exact dynamics of planar closed-chain mechanisms, from model files.",
        epilog=(
            "examples:\n"
            "  planardyn check five-bar                 # a shipped model by name, or a model file\n"
            "  planardyn simulate five-bar -o five-bar.csv\n"
            "  planardyn plot five-bar.csv -o five-bar.png\n"
            "  planardyn plot five-bar.csv --points P -o p.png\n"
            "  planardyn animate five-bar.csv -o five-bar.html\n"
            "  planardyn inverse five-bar --motion five-bar.csv -o torques.csv\n"
            "  planardyn size five-bar --circle 0.014 0.5097 0.06 --payload 0.5\n"
            "  planardyn docs model-format             # the guide's page on model files\n"
            "  planardyn demo\n\n"
            "Run 'planardyn COMMAND --help' for a command's options, 'planardyn docs' for the guide.\n" + EPILOG
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--version", action="version", version=f"planardyn {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    c = _sub(sub, "check", "describe a model: structure, mobility, coordinates, singularity measures",
             "Load and validate a model file and describe it: bodies, pairs by kind, the coordinates\n"
             "with their units and drawn values, the Grubler mobility 3n - 2p, and the singularity\n"
             "measures at the start configuration.",
             "  planardyn check five-bar\n"
             "  planardyn check my-linkage.yaml")
    c.add_argument("model", type=Path, help=MODEL_HELP)

    d = _sub(sub, "draw", "write a model's drawing for CAD or a document (.svg, .dxf)",
             "Write the mechanism as drawn: SVG (the plot's drawing) or DXF in millimetres on the\n"
             "layers BODIES, PAIRS, GROUND and LABELS (DXF needs the 'cad' extra, ezdxf).",
             "  planardyn draw five-bar -o five-bar.svg\n"
             "  planardyn draw my-linkage.yaml -o my-linkage.dxf")
    d.add_argument("model", type=Path, help=MODEL_HELP)
    d.add_argument("-o", "--output", type=Path, required=True, help="the drawing: .svg or .dxf")

    s = _sub(sub, "simulate", "simulate a model file and write the trajectory (.csv, .parquet, .npz)",
             "Integrate the equations of motion from the model's start state. Options left out take\n"
             "the model file's 'simulate' values, else the defaults shown. The results file holds\n"
             "the model, the settings and the planardyn version, so it can be re-plotted and the\n"
             "run reproduced.",
             "  planardyn simulate five-bar -o five-bar.csv\n"
             "  planardyn simulate slider-crank --t-end 2 --method radau5 -o run.npz\n"
             "  planardyn simulate slider-crank --speed theta=1rev/s -o crank-torque.csv\n"
             "  planardyn simulate my-linkage.yaml --method rk4 --dt 1e-3 --output-dt 0.01 -o run.parquet")
    s.add_argument("model", type=Path, help=MODEL_HELP)
    s.add_argument("--t-end", type=_setting("t_end"), help="end time (s); default: the model's, else 1")
    s.add_argument("--method", help="dop853 (default), dopri5, radau5 or rk4 (needs --dt)")
    s.add_argument("--rtol", type=_setting("rtol"), help="relative tolerance (default 1e-9)")
    s.add_argument("--atol", type=_setting("atol"), help="absolute tolerance, > 0 (default 1e-12)")
    s.add_argument("--dt", type=_setting("dt"), help="fixed step (s): for rk4, or to switch error control off")
    s.add_argument("--output-dt", type=_setting("output_dt"), help="spacing of the output rows (s); default: the model's, else every step")
    s.add_argument("--max-steps", type=_setting("max_steps"), help="most step attempts before giving up")
    s.add_argument("--speed", action="append", metavar="NAME=RATE", default=[],
                   help="drive coordinate NAME at a constant rate instead of its effort (its torque or force is "
                        "computed): rad/s, rev/s, rpm, deg/s, or m/s, mm/s for a displacement, e.g. crank=1rev/s; "
                        "repeatable")
    s.add_argument("--stop-when", action="append", metavar="NAME=VALUE", default=[], type=_crossing,
                   help="stop when coordinate NAME crosses VALUE (rad or m; NAME>VALUE rising only, NAME<VALUE "
                        "falling only), located on the integrator's interpolant; the last row is at that time "
                        "(status 'event'); repeatable, the first crossing stops")
    s.add_argument("-o", "--output", "--out", type=_results_path, dest="output",
                   help="results file to write: .csv, .parquet or .npz (by extension)")
    s.add_argument("--progress", action="store_true", help="show a progress bar on stderr even when it is not a terminal")
    s.add_argument("--no-progress", action="store_true", help="never show the progress bar")

    i = _sub(sub, "inverse", "drive efforts for a prescribed motion of the coordinates",
             "Inverse dynamics: the drive efforts (N m on angles, N on displacements) that make the\n"
             "mechanism follow a prescribed motion, with the model's loads (gravity, springs,\n"
             "dampers) acting; the model's own drives are not counted. The motion is a CSV table\n"
             "with a column t (s) and one per coordinate (rad or m); rates and accelerations come\n"
             "from cubic splines of q unless columns qd_<name> and qdd_<name> give them. A\n"
             "planardyn results file is also accepted (its q, qd, qdd are used).",
             "  planardyn inverse five-bar --motion motion.csv -o torques.csv\n"
             "  planardyn inverse five-bar --motion five-bar.npz -o check.npz\n"
             "\n"
             "motion.csv:\n"
             "  t,theta1,theta2\n"
             "  0.0,2.0071,1.0472\n"
             "  0.01,2.0080,1.0460\n"
             "  ...")
    i.add_argument("model", type=Path, help=MODEL_HELP)
    i.add_argument("--motion", type=Path, required=True, help="motion table (.csv) or results file")
    i.add_argument("-o", "--output", "--out", type=_results_path, dest="output",
                   help="results file to write (.csv, .parquet or .npz) with tau_<name> columns")

    idf = _sub(sub, "identify", "identify the inertial and friction parameters from a measured motion",
               "Estimate the model's base parameters (the combinations of the inertial parameters,\n"
               "rotor inertias and friction coefficients the efforts can tell apart) from a measured\n"
               "motion: a CSV table with t (s), one column per coordinate (rad or m) and tau_<name>\n"
               "(N m or N; the motor torque where the model has an actuator; tau_motor_<name> columns,\n"
               "when present, are taken instead), or a planardyn results file (its motor torques\n"
               "tau_motor_<name> where the model has actuators, else tau_<name>). Rates and\n"
               "accelerations come from qd_<name>/qdd_<name> columns, else from the positions\n"
               "low-pass filtered at --cutoff (the efforts filtered alike). Prints each base\n"
               "parameter identified with its standard error, against the model's.",
               "  planardyn identify five-bar measured.csv --cutoff 10\n"
               "  planardyn identify five-bar run.npz --validate other.npz -o identified.json")
    idf.add_argument("model", type=Path, help=MODEL_HELP)
    idf.add_argument("data", type=Path, help="measured motion: CSV table or results file")
    idf.add_argument("--cutoff", type=number(1e-6, 1e9), help="low-pass cutoff (Hz) to differentiate positions")
    idf.add_argument("--validate", type=Path, help="another measured motion: RMS effort error, identified vs model")
    idf.add_argument("-o", "--output", type=Path, help="write the identification as JSON")

    pl = _sub(sub, "plot", "plot a results file: coordinates, rates, drive efforts, energy; or points' motions",
              "Plot the time histories of a results file (coordinates, rates, drive efforts and\n"
              "energy on one figure), or with --torque-speed each drive's effort against its speed,\n"
              "or with --points the position, velocity and acceleration of named points (a ram's\n"
              "stroke, an end effector's path) against time, each point's range printed.",
              "  planardyn plot five-bar.csv                 # writes five-bar.png\n"
              "  planardyn plot five-bar.npz -o histories.png\n"
              "  planardyn plot five-bar.csv --torque-speed -o torque-speed.png\n"
              "  planardyn plot slider-crank.csv --points B -o stroke.png")
    pl.add_argument("results", type=Path, help="results file (.csv, .parquet or .npz) written by planardyn")
    pl.add_argument("-o", "--output", type=Path, help="image to write (.png, .pdf, .svg); default RESULTS with .png")
    what = pl.add_mutually_exclusive_group()
    what.add_argument("--torque-speed", action="store_true", help="plot drive effort against speed instead")
    what.add_argument("--points", nargs="+", metavar="POINT",
                      help="plot these points' position, velocity and acceleration (m, m/s, m/s^2) against time instead")
    pl.add_argument("--dpi", type=number(*DPI_RANGE), default=120,
                    help=f"resolution of raster images, {DPI_RANGE[0]:g} to {DPI_RANGE[1]:g} (default 120)")

    a = _sub(sub, "animate", "animate a result: GIF, MP4 or the browser app with the run loaded",
             "Animate the mechanism along a results file. .gif and .mp4 are videos (MP4 needs\n"
             "imageio-ffmpeg); .html is the browser app (as planardyn app --results writes it) with\n"
             "the run ready to play, scrub and chart, and the model to drag, edit and simulate: one\n"
             "offline file for any browser.",
             "  planardyn animate five-bar.csv -o five-bar.gif       # the model from the file\n"
             "  planardyn animate five-bar five-bar.csv -o five-bar.html\n"
             "  planardyn animate five-bar.npz -o five-bar.mp4 --fps 30 --speed 0.5")
    a.add_argument("files", type=Path, nargs="+", metavar="[MODEL] RESULTS",
                   help="results file (.csv, .parquet or .npz), after the model it was computed with when "
                        "the file does not hold its model (files planardyn writes do)")
    a.add_argument("-o", "--output", type=Path, required=True, help="FILE.gif, FILE.mp4 or FILE.html")
    a.add_argument("--fps", type=number(1e-3, MAX_FPS), default=20.0,
                   help=f"frames per second of playback, up to {MAX_FPS:g} (default 20)")
    a.add_argument("--speed", type=number(1e-12, 1e12), help="simulated seconds per second of playback (default: the run lasts 3-10 s)")
    a.add_argument("--trace", action="append", metavar="POINT", help="trace this point's path (repeat; default: the loop's moving joints)")
    a.add_argument("--channel", action="append", metavar="NAME", help="HTML: channel charted at first (repeat; e.g. theta1, tau_theta1, kinetic)")

    d = _sub(sub, "demo", "show what planardyn does: a robot's path, torques, sizing, singularities; a mechanism moving",
             "Write, into one folder and in seconds, from the shipped models: the 5R robot tracing a\n"
             "circle with its drive torques, actuator sizing report and singularity map; a passive\n"
             "mechanism (a four-bar under gravity) simulated, plotted and animated; and both in the\n"
             "browser app (HTML, open it in a browser). One line per file says what it is.",
             "  planardyn demo\n"
             "  planardyn demo --out /tmp/demo --model slider-crank")
    d.add_argument("--out", type=Path, default=Path("out/demo"), help="output folder (default out/demo)")
    d.add_argument("--model", type=Path, help="model file or shipped name for the passive part (default four-bar-gravity)")
    w = _sub(sub, "app", "write the browser app: drag, edit and simulate a model in one offline HTML file",
             "Write one HTML file holding planardyn's engine as WebAssembly and the model: open it in a\n"
             "browser (no server, no network) to drag a point or a coordinate and see the drive\n"
             "efforts, pair reactions, singularity measure and point paths follow; edit the model with\n"
             "the loader's errors in place; simulate, play, chart every channel and export. With\n"
             "--results, a run computed in Python is in the page too, ready to play.",
             "  planardyn app five-bar -o five-bar.html\n"
             "  planardyn app my-linkage.yaml -o app.html\n"
             "  planardyn app four-bar-gravity --results run.csv -o run.html")
    w.add_argument("model", nargs="?", type=Path, default=Path("five-bar"), help=MODEL_HELP + "; default five-bar")
    w.add_argument("-o", "--output", "--out", type=Path, dest="output", default=Path("app.html"),
                   help="the HTML file to write (default app.html)")
    w.add_argument("--results", type=_results_path, help="a results file of the model (.csv, .parquet, .npz) to play")
    w.set_defaults(run=_app)
    size_command(sub)
    stiffness_commands(sub)
    _plan_command(sub, full=command == "plan")
    exchange_commands(sub)
    g = _sub(sub, "docs", "the user guide, installed with planardyn: list its pages, or print one",
             "Without PAGE, list the guide's pages with their titles and the folder they are installed\n"
             "in; with PAGE, print that page (Markdown). The same pages as the docs/ folder of the\n"
             "repository and the site built from it.",
             "  planardyn docs\n"
             "  planardyn docs model-format | less\n"
             "  planardyn docs cli --path               # where the file is, to open it in an editor")
    g.add_argument("page", nargs="?", help="a page's name: model-format, cli, api, robot, ...")
    g.add_argument("--path", action="store_true", help="print the page's file name instead of its text")
    g.set_defaults(run=_docs)
    return p


def _plan_command(sub: argparse._SubParsersAction, full: bool) -> None:
    """``plan``: in full (its options, from planardyn.plan.cli) when it is the command to run,
    else its line in the listing; without the 'plan' extra, a command that says how to get it."""
    cause = None
    if full:
        try:
            from .plan.cli import register
        except ImportError as e:
            if not extras.is_missing("plan", e):
                raise
            cause = e
        else:
            register(sub, PLAN_HELP)
            return
    # Every argument is taken ('-' is no option prefix here): the run says what to install.
    stub = sub.add_parser("plan", help=PLAN_HELP, add_help=False, prefix_chars="\x00")
    stub.add_argument("arguments", nargs="*")
    stub.set_defaults(run=_plan_missing, cause=cause)


def _plan_missing(args: argparse.Namespace) -> int:
    raise extras.missing("plan", "planardyn plan", args.cause)


# ------------------------------------------------------------------ commands


def _check(args: argparse.Namespace) -> int:
    mech = load(args.model)
    n, pairs = mech.n_bodies, mech.pairs
    s = structure.analyse(mech)
    shipped = Path(args.given) != args.model  # a name: the file's path would be the package's
    print(f"model: {mech.name}  ({f'shipped model {args.given}' if shipped else mech.source})")
    print(f"bodies: {n}")
    for b, mass, inertia in zip(mech.body_names, mech.masses, mech.inertias):
        print(f"  {b}: mass {mass:.6g} kg, inertia {inertia:.6g} kg m^2")
    print(dimensions.report(mech, dimensions.constructed_points(args.model)))
    kinds: dict[str, list[str]] = {}
    for pr in pairs:
        kinds.setdefault(pr["kind"], []).append(pr["name"])
    print(f"pairs: {len(pairs)}  (" + ", ".join(f"{len(v)} {k}" for k, v in kinds.items()) + ")")
    for k, names in kinds.items():
        print(f"  {k}: {', '.join(names)}")
    print(f"mobility (Grubler): {structure.grubler_formula(s)}; coordinates: {mech.dof}")
    print("coordinates:")
    for name, unit, drawn, q0 in zip(mech.coordinate_names, mech.coordinate_units, mech.drawn_q, mech.q0):
        start = "" if drawn == q0 else f", start {q0:.6g} {unit}"
        print(f"  {name}: drawn {drawn:.6g} {unit}{start}")
    try:
        kin = mech.kinematics(mech.q0)
        print(f"singularity measures at the start (0 = singular): type II sigma_min {kin['sigma_min']:.4g}, "
              f"passive {kin['sigma_passive']:.4g}")
        print(f"loop-closure residual at the start: {kin['residual']:.3g}")
    except SingularityError as e:
        print(f"singularity measures at the start: singular ({e})")
    print(structure.report(s))
    return EXIT_OK


def _draw(args: argparse.Namespace) -> int:
    if args.output.suffix.lower() not in (".svg", ".dxf"):
        raise UsageError(f"-o {args.output}: a drawing is written as SVG or DXF; give a file ending in .svg or .dxf")
    require_writer(args.output)
    mech = load(args.model)
    print(f"wrote {drawing.write_drawing(mech, args.output)}")
    return EXIT_OK


def _simulate(args: argparse.Namespace) -> int:
    from .results_io import attach_metadata, simulate_settings, write_results

    mech = load(args.model)
    settings = simulate_settings(
        mech, t_end=args.t_end, method=args.method, rtol=args.rtol, atol=args.atol, dt=args.dt,
        output_dt=args.output_dt, max_steps=args.max_steps,
    )
    if (settings["method"] or "").lower() in FIXED_STEP_METHODS and settings["dt"] is None:
        raise UsageError(f"--method {settings['method']} takes fixed steps: give the step with --dt (e.g. --dt 1e-3; "
                         "or dt in the model file's simulate section), or choose an adaptive method (--method dopri5)")
    require_writer(args.output)
    motion = _speeds(args.speed, mech)
    for c in args.stop_when:
        if c.coordinate not in mech.coordinate_names:
            raise UsageError(f"--stop-when {c.coordinate}...: give NAME=VALUE with NAME one of "
                             f"{', '.join(mech.coordinate_names)}")
    t_end = settings["t_end"] or 1.0
    if settings["output_dt"] is not None:
        refused = rows_message(t_end / settings["output_dt"] + 1, mech.dof, mech.n_bodies, available_memory())
        if refused:
            raise UsageError(f"{args.model}: {refused}: give a larger --output-dt or a shorter --t-end")
    show = not args.no_progress and (args.progress or sys.stderr.isatty())
    bar = ProgressBar(t_end) if show else None
    try:
        with RunGuard(bar) as guard:
            res = mech.simulate(**settings, progress=guard, motion=motion, events=args.stop_when or None)
        if bar is not None and res.success:
            bar(t_end)
    finally:
        if bar is not None:
            bar.close()
    if guard.reason is not None and res.status == "cancelled":
        res = dataclasses.replace(res, message=guard.reason)
    stops = {"events": [dataclasses.asdict(c) for c in args.stop_when]} if args.stop_when else {}
    res = attach_metadata(res, mech, dict(settings, motion=motion, **stops))
    if args.output is not None:
        with writing(args.output):
            write_results(res, args.output)
    line = summary(res) + (f" -> {args.output}" if args.output is not None else "")
    print(line)
    if not res.success:
        print(f"planardyn: simulation stopped early: {res.message}", file=sys.stderr)
        return EXIT_FAILED
    return EXIT_OK


def _speeds(given: list[str], mech: Mechanism) -> dict[str, float] | None:
    """``--speed NAME=RATE`` options as ``Mechanism.simulate``'s ``motion`` (rates in SI)."""
    from .units import parse_rate

    motion: dict[str, float] = {}
    for text in given:
        name, _, rate = text.partition("=")
        if name not in mech.coordinate_names:
            raise UsageError(f"--speed {text}: give NAME=RATE with NAME one of {', '.join(mech.coordinate_names)}")
        if name in motion:
            raise UsageError(f"--speed {text}: {name} already has a speed: give each coordinate's --speed once")
        try:
            motion[name] = parse_rate(rate, mech.coordinate_kinds[mech.coordinate_names.index(name)])
        except ValueError as e:
            raise UsageError(f"--speed {text}: {e}") from None
    return motion or None


def _inverse(args: argparse.Namespace) -> int:
    import numpy as np

    from .results_io import inverse_from_file, write_results

    require_writer(args.output)
    mech = load(args.model)
    res = inverse_from_file(mech, args.motion)
    if args.output is not None:
        with writing(args.output):
            write_results(res, args.output)
    peaks = ", ".join(
        f"|tau_{n}| <= {v:.4g} {u}" for n, v, u in zip(mech.coordinate_names, np.abs(res.tau).max(axis=0), mech.effort_units)
    )
    print(f"inverse dynamics: {len(res.t)} rows, t = {res.t[0]:.6g}..{res.t[-1]:.6g} s, {peaks}, "
          f"min sigma {float(res.sigma.min()):.3g}; branch: {res.metadata['branch']}"
          + (f" -> {args.output}" if args.output else ""))
    return EXIT_OK


def _measured(mech: Any, path: Path, cutoff: float | None) -> tuple[Any, ...]:
    """q, qd, qdd, tau, x of a measured motion (rates from columns, or differentiated)."""
    from .identify import differentiate, inside, lowpass
    from .results_io import read_motion

    m = read_motion(path, mech.coordinate_names)
    # The regressor's rows are motor torques where the model has actuators.
    tau = m["tau_motor"] if m["tau_motor"] is not None else m["tau"]
    if tau is None:
        names = ", ".join(f"tau_{n}" for n in mech.coordinate_names)
        raise UsageError(f"{path}: identification needs the measured efforts: columns {names}")
    if m["tau_motor"] is None and m["from_results"] and any(a is not None for a in mech.actuators):
        raise UsageError(f"{path}: a results file without motor torques (no tau_motor_<name> columns: format "
                         "version 2 or older): its tau is joint-side, while the model's actuators need the motor "
                         "torques; save the run again with this planardyn, or give the motor torques as tau_<name> "
                         "in a table")
    if m["qd"] is not None and m["qdd"] is not None:
        return m["q"], m["qd"], m["qdd"], tau, m["x"]
    if cutoff is None:
        raise UsageError(f"{path}: no qd_/qdd_ columns: give --cutoff (Hz) to differentiate the positions")
    with _about(path):
        q, qd, qdd = differentiate(m["t"], m["q"], cutoff)
        keep = inside(m["t"], cutoff)
        if not keep.any():
            raise UsageError(f"{path}: a record of {m['t'][-1] - m['t'][0]:g} s is all filter transient at "
                             f"--cutoff {cutoff:g} Hz: record longer or raise --cutoff")
        return q[keep], qd[keep], qdd[keep], lowpass(m["t"], tau, cutoff)[keep], None


@contextlib.contextmanager
def _about(path: Path) -> Iterator[None]:
    """The errors of computing on a data file (its data, or an argument from an option) as
    usage errors naming the file; the one option that reaches the computation, ``--cutoff``,
    named as the user wrote it."""
    try:
        yield
    except DataError as e:
        raise UsageError(str(e) if getattr(e, "path", None) else f"{path}: {e}") from None
    except ArgumentError as e:
        text = f"--{e}" if getattr(e, "argument", None) == "cutoff" else str(e)
        raise UsageError(f"{path}: {text}") from None


@contextlib.contextmanager
def _options(options: dict[str, str]) -> Iterator[None]:
    """An ArgumentError of an API argument that an option gave, as a usage error naming the
    option (``options``: argument name -> option)."""
    try:
        yield
    except ArgumentError as e:
        option = options.get(getattr(e, "argument", None) or "")
        if option is None:
            raise
        raise UsageError(f"{option}: {e}") from None


def _identify(args: argparse.Namespace) -> int:
    import numpy as np

    from .identify import identify

    require_writer(args.output)
    mech = load(args.model)
    measured = _measured(mech, args.data, args.cutoff)
    # Both records read before the identification: a bad --validate is refused at once.
    validation = None if args.validate is None else _measured(mech, args.validate, args.cutoff)
    with _about(args.data):
        found = identify(mech, *measured)
    print(found.report())
    if validation is not None:
        q, qd, qdd, tau, x = validation
        with _about(args.validate):
            Y, tau_o = mech.regressor(q, qd, qdd, x=x)
        rms = lambda e: float(np.sqrt(np.mean(e**2)))  # noqa: E731
        ident = rms(Y[..., found.base.independent] @ found.beta + tau_o - tau)
        prior = rms(Y @ np.array(list(mech.regressor_parameters.values())) + tau_o - tau)
        print(f"validation on {args.validate}: RMS effort error {ident:.4g} identified, {prior:.4g} with the model")
    if args.output is not None:
        out = {"base_parameters": found.base.expressions, "identified": found.beta.tolist(),
               "std_error": found.std_error.tolist(), "model": found.prior.tolist(),
               "parameters": {k: float(v) for k, v in found.pi.items()},
               "residual_rms": found.residual_rms.tolist(), "samples": found.samples}
        with writing(args.output):
            args.output.write_text(json.dumps(out, indent=1))
        print(f"wrote {args.output}")
    return EXIT_OK


def _plot(args: argparse.Namespace) -> int:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from .plot import plot_point_motion, plot_results, plot_torque_speed
    from .results_io import read_results

    out = args.output or args.results.with_suffix(".png")
    require_writer(out)
    res = read_results(args.results)
    if args.points:
        motion = _point_motion(res, args.results, args.points)
        fig = Figure(figsize=(9, 8))
        FigureCanvasAgg(fig)
        with _options({"points": "--points"}):
            plot_point_motion(motion, args.points, fig=fig)
        for name in args.points:
            print(motion.describe(name))
    elif args.torque_speed:
        fig = Figure(figsize=(7, 5))
        FigureCanvasAgg(fig)
        ax = fig.add_subplot()
        plot_torque_speed(res, ax=ax)
        name = (res.metadata.get("model") or {}).get("name") or args.results.name
        ax.set_title(f"{name}: drive effort vs speed")
        fig.tight_layout()
    else:
        fig = Figure(figsize=(11, 7))
        FigureCanvasAgg(fig)
        plot_results(res, fig=fig)
    try:
        with writing(out):
            fig.savefig(out, dpi=args.dpi)
    except ValueError as e:  # matplotlib: an image format it does not write
        raise UsageError(f"{out}: {e}") from None
    print(f"wrote {out}")
    return EXIT_OK


def _point_motion(res: SimulationResult, path: Path, points: list[str]) -> Any:
    """The motion of the named points along a results file's run (its model from the file)."""
    if res.metadata.get("model") is None:
        raise UsageError(f"{path} does not hold its model, which --points needs: simulate it again with "
                         "planardyn simulate (its results files hold the model)")
    mech = from_result(res)
    motion = mech.point_motion(res)
    unknown = [p for p in points if p not in motion.names]
    if unknown:
        raise UsageError(f"--points: the model has no point {', '.join(unknown)}; its points are "
                         f"{', '.join(motion.names)}")
    # A point the ground carries is reported as the ground's, at rest, even where a moving
    # body carries it too (a slider's point on its guide): refused rather than drawn still.
    shared = [p for p in points if p in mech.ground_points and any(p in [n for n, _ in b] for b in mech.body_points)]
    if shared:
        bodies = [mech.body_names[k] for k, b in enumerate(mech.body_points) if shared[0] in [n for n, _ in b]]
        raise UsageError(f"--points {shared[0]}: the ground carries {shared[0]} as well as {' and '.join(bodies)}, "
                         "and a point's motion is its ground copy's, at rest: give a point the ground does not carry "
                         f"(add one at the same place to the points of {' or '.join(bodies)} in the model file)")
    return motion


def _app(args: argparse.Namespace) -> int:
    from .app import write_app
    from .results_io import read_results

    if args.output.suffix.lower() not in (".html", ".htm"):
        raise UsageError(f"{args.output}: the app is an .html file")
    mech = load(args.model)
    res = None
    if args.results is not None:
        res = read_results(args.results)
        if res.coordinate_names != mech.coordinate_names or res.body_names != mech.body_names:
            raise UsageError(f"{args.results} was not computed with {args.given}: its coordinates are "
                             f"({', '.join(res.coordinate_names)}), the model's ({', '.join(mech.coordinate_names)})")
    with writing(args.output):
        out = write_app(args.output, args.model, res, mech)
    print(f"{out}: the app for {mech.name} ({out.stat().st_size / 1e6:.1f} MB, one offline file; open it in a browser)")
    return EXIT_OK


def _animate(args: argparse.Namespace) -> int:
    from .animate import FORMATS, animate
    from .results_io import read_results

    if args.output.suffix.lower() not in FORMATS:
        raise UsageError(f"{args.output}: an animation is .gif, .mp4 or .html")
    require_writer(args.output)
    if len(args.files) > 2:
        raise UsageError(f"animate takes [MODEL] RESULTS, got {len(args.files)} files")
    *model, results = args.files
    res = read_results(results)
    if model:
        mech = load(models.resolve(model[0]))
        if res.coordinate_names != mech.coordinate_names or res.body_names != mech.body_names:
            raise UsageError(
                f"{results} was not computed with {model[0]}: its coordinates are "
                f"({', '.join(res.coordinate_names)}), the model's ({', '.join(mech.coordinate_names)})"
            )
    elif res.metadata.get("model") is None:
        raise UsageError(f"{results} does not hold its model: give the model file first, "
                         f"planardyn animate MODEL {results} -o {args.output}")
    else:
        mech = from_result(res)
    kw = {"channels": args.channel} if args.output.suffix.lower() in (".html", ".htm") else {}
    if args.channel and not kw:
        raise UsageError("--channel is for the HTML app only")
    bar: ProgressBar | None = None
    if not kw and sys.stderr.isatty():  # GIF and MP4 take seconds: a bar over the frames, made at the first
        def frames(done: int, total: int) -> None:
            nonlocal bar
            bar = bar or ProgressBar(total, unit="frames")
            bar(done)

        kw["progress"] = frames
    start = time.monotonic()
    try:
        with writing(args.output), _options({"traces": "--trace", "channels": "--channel"}):
            animate(mech, res, args.output, fps=args.fps, speed=args.speed, traces=args.trace, **kw)
    finally:
        if bar is not None:
            bar.close()
    size = args.output.stat().st_size
    print(f"wrote {args.output} ({size / 1024:.0f} KiB, {time.monotonic() - start:.1f} s)")
    return EXIT_OK


def _demo(args: argparse.Namespace) -> int:
    from .demo import run

    out: Path = args.out
    if args.model is not None and not Path(args.model).is_file():
        raise UsageError(f"--model {args.model}: not a model file (a file, or a shipped model's name)")
    print(f"planardyn demo: writing into {out}/")
    with writing(out):
        demo = run(out, args.model, echo=lambda line: print("  " + line, flush=True))
    print(f"open {out / 'robot.html'} and {out / 'passive.html'} in a browser to play the motions")
    return EXIT_OK if demo.success else EXIT_FAILED


def _docs(args: argparse.Namespace) -> int:
    if args.page is None:
        if args.path:
            print(guide.directory())
            return EXIT_OK
        print(f"The planardyn guide, {len(guide.pages())} pages in {guide.directory()}; "
              "read one with 'planardyn docs PAGE':")
        for name in guide.pages():
            print(f"  {name:<16} {guide.title(name)}")
        return EXIT_OK
    path = guide.page(args.page)
    if args.path:
        print(path)
    else:
        sys.stdout.write(path.read_text(encoding="utf-8"))
    return EXIT_OK


COMMANDS = {
    "check": _check,
    "draw": _draw,
    "simulate": _simulate,
    "inverse": _inverse,
    "identify": _identify,
    "plot": _plot,
    "animate": _animate,
    "demo": _demo,
}


def main(argv: Sequence[str] | None = None) -> int:
    with warnings.catch_warnings():  # restores showwarning for a caller in the same process
        warnings.showwarning = _warning_line
        return _main(list(sys.argv[1:] if argv is None else argv))


def _main(argv: list[str]) -> int:
    try:
        try:
            args = _parser(argv[0] if argv else None).parse_args(argv)
        except SystemExit as e:  # argparse: --help, --version (0) or a usage error (2), already printed
            return e.code if isinstance(e.code, int) else EXIT_OK if e.code is None else EXIT_USAGE
        if getattr(args, "model", None) is not None:
            args.given = str(args.model)
            try:
                args.model = models.resolve(args.model)
            except models.UnknownModelError as e:  # demo's model is an option, the others' an argument
                raise UsageError(f"--model {e}" if args.command == "demo" else str(e)) from None
        code = getattr(args, "run", None) or COMMANDS[args.command]
        code = code(args)
        sys.stdout.flush()
        return code
    except BrokenPipeError:
        # The reader of stdout stopped (planardyn check ... | head -1): nothing left to say.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    except (AssemblyError, SingularityError) as e:
        # The start state (or a row of a motion) could not be computed: the computation failed.
        return _fail(str(e), EXIT_FAILED)
    except (PlanardynError, UsageError, ValueError, OSError, ImportError, models.UnknownModelError,
            guide.UnknownPageError) as e:
        return _fail(str(e), EXIT_USAGE)
    except MemoryError:
        return _fail("out of memory: ask for fewer outputs (--output-dt, --t-end) or a smaller image", EXIT_FAILED)
    except KeyboardInterrupt:
        return _fail("interrupted", 130)
    except Exception as e:  # noqa: BLE001 - the last resort: a message, never a traceback
        return _fail(f"unexpected {type(e).__name__}: {e} (please report this)", EXIT_FAILED)


def _fail(message: str, code: int) -> int:
    print(f"planardyn: {message}", file=sys.stderr)
    return code


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
