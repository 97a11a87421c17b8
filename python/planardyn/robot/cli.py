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


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="planardyn size", description="Actuator sizing of an end-effector motion.")
    p.add_argument("model", help="model file (.yaml/.json), or a shipped model by name (five-bar)")
    p.add_argument("--point", default="P", help="end-effector point (default P)")
    p.add_argument("--body", default=None, help="body carrying it, when several do (3-DOF pose)")
    shape = p.add_mutually_exclusive_group(required=True)
    shape.add_argument("--circle", nargs=3, type=number(unit="m"), metavar=("CX", "CY", "R"),
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
    return p


def size_cli(argv: list[str] | None = None) -> int:
    """Run ``planardyn size`` with ``argv`` (without the program and command names)."""
    parser = _parser()
    try:
        args = parser.parse_args(argv)
        if args.circle and args.circle[2] <= 0:
            parser.error(f"argument --circle: the radius R must be > 0 m, got {args.circle[2]:g}")
    except SystemExit as exc:
        return 0 if exc.code == 0 else 2
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
