"""``planardyn plan``: the time-optimal timing of an end-effector line, from the shell.

    planardyn plan MODEL --line X0 Y0 X1 Y1 --effort T [T ...] [--speed V [V ...]] [--point P]
                   [--spacing M] [--grid N] [-o FILE.csv]

The CSV has ``t`` and per coordinate its value, ``qd_``, ``qdd_`` and ``tau_`` columns at the
grid points: the motion table ``planardyn inverse MODEL --motion FILE.csv`` and
``planardyn simulate`` take. Exit status: 0 done; 1 no timing (limits too low, a
singularity, out of reach); 2 a usage or model error.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from .._core import AssemblyError, ModelError, SingularityError
from ..mechanism import load
from ..models import UnknownModelError, resolve
from ..robot import EndEffector
from .topp import PlanError, TimedPath, task_waypoints, time_optimal


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="planardyn plan", description="Time-optimal timing of an end-effector line.")
    p.add_argument("model", help="model file (.yaml/.json), or a shipped model by name")
    p.add_argument("--point", default="P", help="end-effector point (default P)")
    p.add_argument("--line", nargs=4, type=float, required=True, metavar=("X0", "Y0", "X1", "Y1"), help="m")
    p.add_argument("--effort", nargs="+", type=float, required=True, help="|tau| limit per coordinate (N m or N)")
    p.add_argument("--speed", nargs="+", type=float, default=None, help="|qd| limit per coordinate (rad/s or m/s)")
    p.add_argument("--spacing", type=float, default=0.01, help="inverse kinematics every this many m (default 0.01)")
    p.add_argument("--grid", type=int, default=200, help="grid points in the path parameter (default 200)")
    p.add_argument("-o", "--output", default=None, help="write the timed motion (CSV)")
    return p


def write_csv(plan: TimedPath, path: str) -> None:
    """The timed path at its grid points as a motion CSV (t, q, qd_, qdd_, tau_ columns)."""
    names = plan.mech.coordinate_names
    header = ["t", *names, *(f"qd_{n}" for n in names), *(f"qdd_{n}" for n in names), *(f"tau_{n}" for n in names)]
    table = np.column_stack([plan.t, plan.q, plan.qd, plan.qdd, plan.tau])
    np.savetxt(path, table, delimiter=",", header=",".join(header), comments="", fmt="%.17g")


def plan_cli(argv: list[str] | None = None) -> int:
    """Run ``planardyn plan`` with ``argv`` (without the program and command names)."""
    try:
        args = _parser().parse_args(argv)
    except SystemExit as exc:
        return 0 if exc.code == 0 else 2
    try:
        mech = load(resolve(args.model))
        ee = EndEffector(mech, args.point)
        q = task_waypoints(ee, [args.line[:2], args.line[2:]], args.spacing)
        plan = time_optimal(mech, q, args.effort, args.speed, n_grid=args.grid)
    except PlanError as exc:
        print(f"planardyn plan: {exc}", file=sys.stderr)
        return 1 if "no timing" in str(exc) else 2
    except (ModelError, ValueError, UnknownModelError) as exc:
        print(f"planardyn plan: {exc}", file=sys.stderr)
        return 2
    except (SingularityError, AssemblyError) as exc:
        print(f"planardyn plan: refused: {exc}", file=sys.stderr)
        return 1
    peak = np.abs(plan.tau).max(axis=0)
    print(f"{mech.name}: {plan.duration:.6g} s along the line ({len(plan.t)} grid points); "
          f"peak |tau| {np.round(peak, 4).tolist()}")
    if args.output:
        write_csv(plan, args.output)
        print(f"wrote {args.output}")
    return 0
