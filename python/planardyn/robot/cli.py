"""``planardyn size``: the actuator sizing report of an end-effector motion, from the shell.

    planardyn size MODEL [--point P] (--circle CX CY R | --line X0 Y0 X1 Y1) [--duration T]
                   [--profile quintic|trapezoid|constant] [--payload KG] [--dt S] [--plot PNG] [--json FILE]

The report is the one ``planardyn.robot.size(EndEffector(mech, point, body), path, ...)``
gives, with the same defaults (``--dt`` unset: solve_motion's). Exit status: 0 done; 1 the
motion is refused (a singularity, out of reach: the message says where); 2 a usage or model
error, or a sampling too coarse for the path (the message gives a --dt that resolves it).
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from .._core import AssemblyError, ModelError, SingularityError
from ..mechanism import load
from ..models import UnknownModelError, resolve
from ..results_format import WriteError, check_writable, writing
from .cli_options import number, positive
from .effector import EndEffector
from .paths import circle, line
from .plots import plot_sizing
from .sampling import SizingError
from .sizing import DISTRIBUTIONS, size

DESCRIPTION = ("Actuator sizing of an end-effector motion: the end-effector point (--point) runs a circle or\n"
               "a line in --duration seconds with a time law (--profile); the report gives each drive's peak\n"
               "and RMS effort, peak speed and power (the motor side and its limits where the model has\n"
               "actuators) and the motion's nearest approach to each singularity.")
EXAMPLES = ("examples:\n"
            "  planardyn size five-bar --circle 0.014 0.5097 0.06 --payload 0.5\n"
            "  planardyn size five-bar --line -0.08 0.28 0.08 0.36 --duration 0.5 --plot sizing.png --json sizing.json\n"
            "\nExit status: 0 done; 1 the motion is refused (a singularity, out of reach); 2 a usage or model\n"
            "error, or a sampling too coarse for the path (the message gives a --dt that resolves it).")


class _Circle(argparse.Action):
    """--circle CX CY R, refused (as argparse refuses an option) unless R > 0."""

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace, values: Any,
                 option_string: str | None = None) -> None:
        if values[2] <= 0:
            raise argparse.ArgumentError(self, f"the radius R must be > 0 m, got {values[2]:g}")
        setattr(namespace, self.dest, values)


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``planardyn size`` on parser ``p``."""
    p.add_argument("model", help="model file (.yaml/.json), or a shipped model by name (five-bar)")
    p.add_argument("--point", default="P", help="end-effector point (default P)")
    p.add_argument("--body", default=None, help="body carrying it, when several do (3-DOF pose)")
    shape = p.add_mutually_exclusive_group(required=True)
    shape.add_argument("--circle", nargs=3, type=number(unit="m"), metavar=("CX", "CY", "R"), action=_Circle,
                       help="circle, m (R > 0)")
    shape.add_argument("--line", nargs=4, type=number(unit="m"), metavar=("X0", "Y0", "X1", "Y1"), help="line, m")
    p.add_argument("--duration", type=positive("s"), default=1.0, help="s (default 1)")
    p.add_argument("--profile", default="quintic", choices=["quintic", "trapezoid", "constant"])
    p.add_argument("--payload", type=number(0.0, unit="kg"), default=0.0, help="kg at the end-effector point")
    p.add_argument("--dt", type=positive("s"), default=None,
                   help="sample spacing, s (default solve_motion's, 1 ms); refused when too coarse for the path")
    p.add_argument("--distribution", default="min_norm", choices=list(DISTRIBUTIONS),
                   help="with redundant actuators: how their efforts are shared (default min_norm)")
    p.add_argument("--preload", type=number(unit="N m or N"), nargs="+", default=None, metavar="LAMBDA",
                   help="with --distribution preload: N m or N along each internal force")
    p.add_argument("--plot", default=None, help="write the report's figure (PNG, PDF...)")
    p.add_argument("--json", default=None, help="write the numbers as JSON")


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``size`` to the planardyn command's subparsers (it sets ``run``)."""
    p = sub.add_parser("size", help="actuator sizing for an end-effector motion: peak and RMS efforts, speeds, power",
                       description=DESCRIPTION, epilog=EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_arguments(p)
    p.set_defaults(run=run)


def size_cli(argv: list[str] | None = None) -> int:
    """Run ``planardyn size`` with ``argv`` (without the program and command names)."""
    parser = argparse.ArgumentParser(prog="planardyn size", description=DESCRIPTION, epilog=EXAMPLES,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    add_arguments(parser)
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:
        return 0 if exc.code == 0 else 2
    return run(args)


def run(args: argparse.Namespace) -> int:
    """``planardyn size`` on parsed arguments; the exit status."""
    try:
        for out in (args.json, args.plot):
            if out:
                check_writable(out)
    except WriteError as exc:
        print(f"planardyn size: {exc}", file=sys.stderr)
        return 2
    try:
        ee = EndEffector(load(resolve(args.model)), args.point, args.body)
        if args.circle:
            path = circle(args.circle[:2], args.circle[2], args.duration, profile=args.profile)
        else:
            path = line(args.line[:2], args.line[2:], args.duration, profile=args.profile)
        options = {} if args.dt is None else {"dt": args.dt}
        report = size(ee, path, payload=args.payload, distribution=args.distribution, preload=args.preload, **options)
    except SizingError as exc:
        option = f"--{exc.argument}: " if exc.argument in ("dt", "payload", "preload", "distribution") else ""
        print(f"planardyn size: {option}{str(exc).removeprefix(f'{exc.argument}: ')}", file=sys.stderr)
        return 2
    except (ModelError, ValueError, UnknownModelError) as exc:
        print(f"planardyn size: {exc}", file=sys.stderr)
        return 2
    except (SingularityError, AssemblyError) as exc:
        print(f"planardyn size: refused: {exc}", file=sys.stderr)
        return 1
    print(report)
    try:
        if args.json:
            with writing(args.json) as out, open(out, "w") as f:
                json.dump(report.to_dict(), f, indent=2)
        if args.plot:
            from matplotlib.figure import Figure

            fig = Figure(figsize=(11, 7))
            plot_sizing(report, fig)
            with writing(args.plot) as out:
                fig.savefig(out, dpi=100)
    except WriteError as exc:
        print(f"planardyn size: {exc}", file=sys.stderr)
        return 1
    return 0
