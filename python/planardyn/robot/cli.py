"""``planardyn size``: the actuator sizing report of an end-effector motion, from the shell.

    planardyn size MODEL [--point P] (--circle CX CY R | --line X0 Y0 X1 Y1) [--duration T]
                   [--profile quintic|trapezoid|constant] [--payload KG] [--plot PNG] [--json FILE]

Exit status: 0 done; 1 the motion is refused (a singularity, out of reach: the message says
where); 2 a usage or model error.
"""

from __future__ import annotations

import argparse
import json
import sys

from .._core import AssemblyError, ModelError, SingularityError
from ..mechanism import load
from ..models import UnknownModelError, resolve
from .effector import EndEffector
from .paths import circle, line
from .plots import plot_sizing
from .sizing import size


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="planardyn size", description="Actuator sizing of an end-effector motion.")
    p.add_argument("model", help="model file (.yaml/.json), or a shipped model by name (five-bar)")
    p.add_argument("--point", default="P", help="end-effector point (default P)")
    p.add_argument("--body", default=None, help="body carrying it, when several do (3-DOF pose)")
    shape = p.add_mutually_exclusive_group(required=True)
    shape.add_argument("--circle", nargs=3, type=float, metavar=("CX", "CY", "R"), help="circle, m")
    shape.add_argument("--line", nargs=4, type=float, metavar=("X0", "Y0", "X1", "Y1"), help="line, m")
    p.add_argument("--duration", type=float, default=1.0, help="s (default 1)")
    p.add_argument("--profile", default="quintic", choices=["quintic", "trapezoid", "constant"])
    p.add_argument("--payload", type=float, default=0.0, help="kg at the end-effector point")
    p.add_argument("--dt", type=float, default=1e-3, help="sample spacing, s")
    p.add_argument("--distribution", default="min_norm", choices=["min_norm", "min_max", "preload"],
                   help="with redundant actuators: how their efforts are shared (default min_norm)")
    p.add_argument("--preload", type=float, nargs="+", default=None, metavar="LAMBDA",
                   help="with --distribution preload: N m or N along each internal force")
    p.add_argument("--plot", default=None, help="write the report's figure (PNG, PDF...)")
    p.add_argument("--json", default=None, help="write the numbers as JSON")
    return p


def size_cli(argv: list[str] | None = None) -> int:
    """Run ``planardyn size`` with ``argv`` (without the program and command names)."""
    try:
        args = _parser().parse_args(argv)
    except SystemExit as exc:
        return 0 if exc.code == 0 else 2
    try:
        ee = EndEffector(load(resolve(args.model)), args.point, args.body)
        if args.circle:
            path = circle(args.circle[:2], args.circle[2], args.duration, profile=args.profile)
        else:
            path = line(args.line[:2], args.line[2:], args.duration, profile=args.profile)
        report = size(ee, path, payload=args.payload, dt=args.dt, distribution=args.distribution,
                      preload=args.preload)
    except (ModelError, ValueError, UnknownModelError) as exc:
        print(f"planardyn size: {exc}", file=sys.stderr)
        return 2
    except (SingularityError, AssemblyError) as exc:
        print(f"planardyn size: refused: {exc}", file=sys.stderr)
        return 1
    print(report)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(report.to_dict(), f, indent=2)
    if args.plot:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(11, 7))
        plot_sizing(report, fig)
        fig.savefig(args.plot, dpi=100)
    return 0
