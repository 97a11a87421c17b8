"""``planardyn plan``: the time-optimal timing of an end-effector line, or the optimal
point-to-point motion between its ends, from the shell.

    planardyn plan MODEL --line X0 Y0 X1 Y1 (--effort T [T ...] | --actuators) [--speed V [V ...]] [--point P]
                   [--spacing M] [--grid N] [--rtol R]
                   [--collocate {time,effort} [--duration S] [--intervals N] [--sigma-min S]]
                   [-o FILE.csv]

Without ``--collocate`` the effector follows the line (TOPP), within ``--effort`` limits or
its motors' torque-speed envelopes (``--actuators``); with ``--collocate``, only the line's ends
are kept and the motion between them is the minimum-time one, or the minimum-effort one in
``--duration`` seconds (collocation, IPOPT). The CSV has ``t`` and per coordinate its value,
``qd_``, ``qdd_`` and ``tau_`` columns at the grid points (collocation: its nodes): the motion
table ``planardyn inverse MODEL --motion FILE.csv`` and ``planardyn simulate`` take. The
summary line gives the largest fraction of a limit the motion uses on the dense check of its
own path (TOPP: also the final grid and the estimated excess over the optimal time). Exit
status: 0 done; 1 no timing or motion within the limits (limits too low, a duration too
short, a singularity, out of reach) or IPOPT did not converge (its status is printed,
nothing is written); 2 a usage or model error (the message names the option).
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from .. import extras
from .._core import AssemblyError, ModelError, SingularityError
from ..mechanism import load
from ..models import UnknownModelError, resolve
from ..results_format import WriteError, check_writable, writing
from ..robot import EndEffector
from ..robot.cli_options import integer, number, positive
from .collocation import collocate
from .planned import InfeasiblePlan, PlanError, PlannedMotion
from .topp import RTOL, TimedPath, task_waypoints, time_optimal

#: The Python argument each option sets, for naming the option in an argument's error.
OPTIONS = {"effort": "--effort", "speed": "--speed", "spacing": "--spacing", "n_grid": "--grid", "rtol": "--rtol",
           "duration": "--duration", "n_intervals": "--intervals", "sigma_min": "--sigma-min", "X": "--line"}


DESCRIPTION = ("Time-optimal timing of an end-effector line (TOPP, toppra) within effort limits (--effort) or\n"
               "the motors' torque-speed envelopes (--actuators), or with --collocate the optimal motion\n"
               "between the line's ends (minimum time, or minimum effort in --duration; collocation, IPOPT).\n"
               "Needs the 'plan' extra: pip install toppra casadi.")
EXAMPLES = ("examples:\n"
            "  planardyn plan library/five-bar-5r --line -0.08 0.28 0.08 0.36 --effort 3 3 --speed 12 12 -o timed.csv\n"
            "  planardyn plan library/five-bar-5r --line -0.08 0.28 0.08 0.36 --effort 3 3 --collocate time\n"
            "\nExit status: 0 done; 1 no timing or motion within the limits, or IPOPT did not converge\n"
            "(nothing written); 2 a usage or model error (the message names the option).")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``planardyn plan`` on parser ``p``."""
    p.add_argument("model", help="model file (.yaml/.json), or a shipped model by name")
    p.add_argument("--point", default="P", help="end-effector point (default P)")
    p.add_argument("--line", nargs=4, type=number(unit="m"), required=True, metavar=("X0", "Y0", "X1", "Y1"), help="m")
    limits = p.add_mutually_exclusive_group(required=True)
    limits.add_argument("--effort", nargs="+", type=positive("N m or N"), help="|tau| limit per coordinate (N m or N)")
    limits.add_argument("--actuators", action="store_true",
                        help="the model's motors: torque within their torque-speed envelopes (not with --collocate)")
    p.add_argument("--speed", nargs="+", type=positive("rad/s or m/s"), default=None,
                   help="|qd| limit per coordinate (rad/s or m/s)")
    p.add_argument("--spacing", type=positive("m"), default=0.01, help="inverse kinematics every this many m (default 0.01)")
    p.add_argument("--grid", type=integer(3, 10**6), default=200,
                   help="grid points in the path parameter to start with (default 200)")
    p.add_argument("--rtol", type=positive(), default=RTOL,
                   help=f"double the grid until the time changes by less than this fraction (default {RTOL:g})")
    p.add_argument("--collocate", choices=["time", "effort"], default=None,
                   help="free path between the line's ends: minimum time, or minimum effort in --duration")
    p.add_argument("--duration", type=positive("s"), default=None, help="s, for --collocate effort")
    p.add_argument("--intervals", type=integer(2, 10_000), default=40, help="collocation intervals (default 40)")
    p.add_argument("--sigma-min", type=number(0.0, 1.0, open_low=True), default=None,
                   help="type II singularity margin for --collocate, in (0, 1)")
    p.add_argument("-o", "--output", default=None, help="write the timed motion (CSV)")


def register(sub: argparse._SubParsersAction, help: str) -> None:
    """Add ``plan`` to the planardyn command's subparsers (it sets ``run``), listed with ``help``."""
    p = sub.add_parser("plan", help=help,
                       description=DESCRIPTION, epilog=EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_arguments(p)
    p.set_defaults(run=run)


def write_csv(plan: PlannedMotion, path: str) -> None:
    """The planned motion at its grid points as a motion CSV (t, q, qd_, qdd_, tau_ columns)."""
    names = plan.mech.coordinate_names
    header = ["t", *names, *(f"qd_{n}" for n in names), *(f"qdd_{n}" for n in names), *(f"tau_{n}" for n in names)]
    # + 0.0 turns -0.0 (an s'' of the wrong sign's zero) into 0.
    table = np.column_stack([plan.t, plan.q, plan.qd, plan.qdd, plan.tau]) + 0.0
    np.savetxt(path, table, delimiter=",", header=",".join(header), comments="", fmt="%.17g")


def run(args: argparse.Namespace) -> int:
    """``planardyn plan`` on parsed arguments; the exit status."""
    try:
        if args.output:
            check_writable(args.output)
    except WriteError as exc:
        print(f"planardyn plan: {exc}", file=sys.stderr)
        return 2
    try:
        mech = load(resolve(args.model))
        ee = EndEffector(mech, args.point)
        if args.collocate is None:
            q = task_waypoints(ee, [args.line[:2], args.line[2:]], args.spacing)
            effort = "actuators" if args.actuators else args.effort
            plan: PlannedMotion = time_optimal(mech, q, effort, args.speed, n_grid=args.grid, rtol=args.rtol)
            assert isinstance(plan, TimedPath)
            excess = "" if plan.time_error is None else f", estimated excess over the optimal time {plan.time_error:.2g} s"
            what = f"along the line ({len(plan.t)} grid points{excess})"
        elif args.actuators:
            print("planardyn plan: --collocate takes --effort limits, not --actuators", file=sys.stderr)
            return 2
        else:
            start = ee.inverse(args.line[:2])
            end = ee.inverse(args.line[2:], start.q, start.kin["x"])
            plan = c = collocate(mech, start.q, end.q, objective=args.collocate, duration=args.duration,
                                 effort=args.effort, speed=args.speed, sigma_min=args.sigma_min,
                                 n_intervals=args.intervals)
            print(f"IPOPT: {c.status}, {c.iterations} iterations, constraint violation {c.violation:.2g}, "
                  f"stated accuracy of q {c.error.max():.2g}")
            if not c.success:
                print("planardyn plan: IPOPT did not converge: nothing written; try more --intervals or "
                      "other limits", file=sys.stderr)
                return 1
            what = f"between the line's ends, minimum {args.collocate} ({len(plan.t)} nodes)"
    except InfeasiblePlan as exc:
        print(f"planardyn plan: {exc}", file=sys.stderr)
        return 1
    except PlanError as exc:
        option = OPTIONS.get(exc.argument or "")
        print(f"planardyn plan: {f'{option}: ' if option else ''}{exc}", file=sys.stderr)
        return 2
    except (ModelError, ValueError, UnknownModelError) as exc:
        print(f"planardyn plan: {exc}", file=sys.stderr)
        return 2
    except (SingularityError, AssemblyError) as exc:
        print(f"planardyn plan: refused: {exc}", file=sys.stderr)
        return 1
    except ImportError as exc:  # casadi is imported by --collocate only
        if extras.is_missing("plan", exc):
            raise extras.missing("plan", "planardyn plan", exc) from exc
        raise
    peak = np.abs(plan.tau).max(axis=0)
    print(f"{mech.name}: {plan.duration:.6g} s {what}; peak |tau| {np.round(peak, 4).tolist()}; limits used to "
          f"{plan.limit_ratio:.10g} on the dense check")
    for name, value in plan.frequency_rows():
        print(f"  {name}: {value}")
    for part in getattr(plan, "ignored", []):
        print(f"  not planned with: {part}")
    if args.output:
        try:
            with writing(args.output) as path:
                write_csv(plan, str(path))
        except WriteError as exc:
            print(f"planardyn plan: {exc}", file=sys.stderr)
            return 1
        print(f"wrote {args.output}")
    return 0
