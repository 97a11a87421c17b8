"""``planardyn stiffness``, ``planardyn modes`` and ``planardyn flexible``: the stiffness, the
natural frequencies and the run with compliant drives of a model with a ``compliance:``
section, from the shell (docs/stiffness.md).

    planardyn stiffness MODEL --body B [--point P] [--at Q ...] [--load FX FY M] [--gravity]
                          [--length L] [--map X0 X1 Y0 Y1 [--n N] [--plot FILE]]
    planardyn modes MODEL [--at Q ...] [--free-rotors | --passive] [--gravity]
    planardyn flexible MODEL [--t-end T] [--output-dt H] [--method M] [--rtol R] [--atol A] [-o FILE.csv]

Exit status: 0 done; 1 the computation was refused (no assembly, an unstable pose); 2 a usage
or model error (the message names the argument and the fix).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable

import numpy as np

from ._core import ArgumentError, AssemblyError, ModelError, SingularityError
from .mechanism import Mechanism, load
from .models import UnknownModelError, resolve
from .results_format import check_writable, writing
from .robot.cli_options import positive
from .robot.effector import EndEffector
from .stiffness import modes, simulate_flexible, small_oscillations, stiffness, stiffness_map
from .stiffness_plots import plot_stiffness_map

EPILOG = "Exit status: 0 done; 1 refused (no assembly, unstable); 2 usage or model error."


def _at(mech: Mechanism, at: list[float] | None) -> np.ndarray:
    if at is None:
        return np.asarray(mech.q0, dtype=float)
    if len(at) != mech.dof:
        raise ArgumentError(f"--at: give {mech.dof} values, one per coordinate ({', '.join(mech.coordinate_names)}), "
                            f"got {len(at)}")
    return np.asarray(at, dtype=float)


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``stiffness`` and ``modes`` to the planardyn command's subparsers."""
    s = sub.add_parser(
        "stiffness", help="Cartesian stiffness of a point with the model's compliances; maps over the workspace",
        description="The compliance and stiffness (x, y, phi) of a body's point at a pose, in equilibrium with a\n"
                    "load (--load, its geometric term included), the weakest direction; or (--map) the weakest\n"
                    "stiffness and first natural frequency over a grid of end-effector positions.",
        epilog="examples:\n  planardyn stiffness robot.yaml --body platform --point P --load 0 -50 0\n"
               "  planardyn stiffness robot.yaml --body distal_left --point P --map -0.2 0.2 0.3 0.6 --plot map.png\n\n"
               + EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    s.add_argument("model", help="model file with a `compliance:` section, or a shipped model by name")
    s.add_argument("--body", required=True, help="the body whose point is the output")
    s.add_argument("--point", help="the point (default the body's centre of mass)")
    s.add_argument("--at", type=float, nargs="+", metavar="Q", help="coordinates (rad or m; default the start)")
    s.add_argument("--load", type=float, nargs=3, metavar=("FX", "FY", "M"), help="wrench at the point, N N N m")
    s.add_argument("--gravity", action="store_true", help="the model's gravity a load too (its geometric term)")
    s.add_argument("--length", type=positive("m"), help="characteristic length (m) for the weakest direction with rotation")
    s.add_argument("--map", type=float, nargs=4, metavar=("X0", "X1", "Y0", "Y1"), help="map this region, m")
    s.add_argument("--n", type=int, default=20, help="grid points per side of --map (default 20)")
    s.add_argument("--plot", help="--map: write the figure (PNG, PDF...)")
    s.set_defaults(run=_stiffness)
    m = sub.add_parser(
        "modes", help="natural frequencies, damping ratios of the compliant mechanism (or a passive one's swing)",
        description="Natural frequencies, damping ratios and mode shapes about a pose, with the model's\n"
                    "compliances (rotors held, or --free-rotors); --passive: the small oscillations of a passive\n"
                    "mechanism about its equilibrium nearest --at.",
        epilog="examples:\n  planardyn modes robot.yaml --at 0.4 0.4 0.4\n  planardyn modes four-bar-gravity --passive\n\n"
               + EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    m.add_argument("model", help="model file, or a shipped model by name")
    m.add_argument("--at", type=float, nargs="+", metavar="Q", help="coordinates (rad or m; default the start)")
    how = m.add_mutually_exclusive_group()
    how.add_argument("--free-rotors", action="store_true", help="the motors torque-driven (rotors free)")
    how.add_argument("--passive", action="store_true", help="small oscillations about the equilibrium (no compliance)")
    m.add_argument("--gravity", action="store_true",
                   help="about the pose as the equilibrium under the model's gravity (its geometric stiffness)")
    m.set_defaults(run=_modes)
    f = sub.add_parser(
        "flexible", help="simulate with compliant drives (the flexible-joint model) and print its energy balance",
        description="Simulate the model with each elastic drive's rotor a coordinate of its own, joined to its\n"
                    "joint by the transmission's spring and damper (the model's drives are the motor torques),\n"
                    "and print the energy balance E(t) - E(0) = W - D: the motors' work W and the transmission\n"
                    "dampers' loss D (what is left: the model's own dampers and friction, and integration error).",
        epilog="examples:\n  planardyn flexible robot.yaml --t-end 0.5 -o flexible.csv\n\n" + EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    f.add_argument("model", help="model file with `compliance.drives` on coordinates with a rotor, or a shipped model")
    f.add_argument("--t-end", type=positive("s"), default=1.0, help="s (default 1)")
    f.add_argument("--output-dt", type=positive("s"), default=1e-3, help="output every this many s (default 1e-3)")
    f.add_argument("--method", default="dop853", help="integrator (default dop853)")
    f.add_argument("--rtol", type=positive(), default=1e-9, help="relative tolerance (default 1e-9)")
    f.add_argument("--atol", type=positive(), default=1e-12, help="absolute tolerance (default 1e-12)")
    f.add_argument("-o", "--output", help="write t, q, theta, energy, work, dissipated (CSV)")
    f.set_defaults(run=_flexible)


def _guarded(command: str, args: argparse.Namespace, body: Callable[[argparse.Namespace], int]) -> int:
    try:
        return body(args)
    except (ModelError, ArgumentError, UnknownModelError, ValueError, OSError) as exc:
        print(f"planardyn {command}: {exc}", file=sys.stderr)
        return 2
    except (SingularityError, AssemblyError) as exc:
        print(f"planardyn {command}: refused: {exc}", file=sys.stderr)
        return 1


def _stiffness(args: argparse.Namespace) -> int:
    return _guarded("stiffness", args, _run_stiffness)


def _run_stiffness(args: argparse.Namespace) -> int:
    mech = load(resolve(args.model))
    if args.map is not None:
        if args.point is None:
            raise ArgumentError("--map: give the end-effector --point")
        smap = stiffness_map(EndEffector(mech, args.point, args.body), (args.map[0], args.map[1]),
                             (args.map[2], args.map[3]), args.n, gravity=args.gravity)
        print(smap)
        if args.plot:
            from matplotlib.figure import Figure

            fig = Figure(figsize=(11, 4.5))
            axes = fig.subplots(1, 2)
            plot_stiffness_map(smap, axes[0])
            plot_stiffness_map(smap, axes[1], "first_frequency")
            fig.savefig(args.plot, dpi=100)
        return 0
    report = stiffness(mech, _at(mech, args.at), body=args.body, point=args.point, wrench=args.load,
                       gravity=args.gravity)
    print(report)
    if args.length is not None:
        direction, k = report.weakest(args.length)
        print(f"weakest with length {args.length:g} m: {k:.6g} N/m along [{direction[0]:.4f}, {direction[1]:.4f}, "
              f"{direction[2]:.4f}] (x, y, L phi)")
    return 0


def _modes(args: argparse.Namespace) -> int:
    return _guarded("modes", args, _run_modes)


def _run_modes(args: argparse.Namespace) -> int:
    mech = load(resolve(args.model))
    q = _at(mech, args.at)
    if args.passive and args.gravity:
        raise ArgumentError("--gravity: --passive takes the model's gravity always; drop --gravity")
    report = (small_oscillations(mech, q) if args.passive
              else modes(mech, q, free_rotors=args.free_rotors, gravity=args.gravity))
    if args.passive:
        print("equilibrium: " + ", ".join(f"{n} = {v:.6g}" for n, v in zip(mech.coordinate_names, report.q)))
    print(report)
    return 0


def _flexible(args: argparse.Namespace) -> int:
    return _guarded("flexible", args, _run_flexible)


def _run_flexible(args: argparse.Namespace) -> int:
    if args.output:
        check_writable(args.output)
    mech = load(resolve(args.model))
    run = simulate_flexible(mech, args.t_end, args.output_dt, method=args.method, rtol=args.rtol, atol=args.atol)
    e, w, d = run["energy"], run["work"], run["dissipated"]
    balance = np.abs(e - e[0] - w + d).max()
    lag = np.abs(run["theta"] - run["q"][:, _elastic_columns(mech)]).max(axis=0)
    print(f"{mech.name}: flexible-joint run to {run['t'][-1]:.6g} s, {len(run['t'])} outputs")
    print("largest rotor lag (joint side): " + ", ".join(f"{n} {v:.4g}" for n, v in zip(_elastic_names(mech), lag)))
    print(f"energy: E(0) {e[0]:.10g} J, E(end) {e[-1]:.10g} J; motors' work W {w[-1]:.6g} J, "
          f"transmission dampers' loss D {d[-1]:.6g} J")
    print(f"energy balance: largest |E(t) - E(0) - W + D| {balance:.3g} J")
    if args.output:
        names = _elastic_names(mech)
        header = ["t", *mech.coordinate_names, *(f"theta_{n}" for n in names), "energy", "work", "dissipated"]
        table = np.column_stack([run["t"], run["q"], run["theta"], e, w, d])
        with writing(args.output) as path:
            np.savetxt(path, table, delimiter=",", header=",".join(header), comments="", fmt="%.17g")
        print(f"wrote {args.output}")
    return 0


def _elastic_names(mech: Mechanism) -> list[str]:
    """The coordinates whose drives are elastic, in the run's order (``compliance.drives``)."""
    return [d["actuator"] for d in mech.to_dict()["compliance"]["drives"]]


def _elastic_columns(mech: Mechanism) -> list[int]:
    return [mech.coordinate_names.index(n) for n in _elastic_names(mech)]
