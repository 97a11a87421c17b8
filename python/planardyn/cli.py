"""The ``planardyn`` command: a thin wrapper over the Python API.

    planardyn simulate MODEL [--t-end T] [--method M] [--rtol R] [--atol A] [--dt H]
                             [--output-dt H] [--max-steps N] [-o results.csv] [--progress]
    planardyn demo [--out DIR] [--model MODEL]

Exit status: 0 success; 1 the computation failed (the simulation stopped before t_end:
the CSV still holds the trajectory computed); 2 a usage, file or model error. Errors are
one message on stderr, never a traceback.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TextIO

from . import AssemblyError, PlanardynError, SingularityError, load
from .result import SimulationResult

EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2

#: The demo's model, in the source tree next to the package (an editable install).
DEMO_MODEL = Path(__file__).resolve().parents[2] / "examples" / "models" / "five-bar.yaml"


class ProgressBar:
    """A one-line text bar on a stream, redrawn from the simulation's progress callback."""

    WIDTH = 30

    def __init__(self, t_end: float, stream: TextIO = sys.stderr) -> None:
        self.t_end, self.stream, self.start = t_end, stream, time.monotonic()

    def __call__(self, t: float) -> None:
        frac = min(max(t / self.t_end, 0.0), 1.0) if self.t_end > 0 else 1.0
        filled = int(round(frac * self.WIDTH))
        bar = "#" * filled + "." * (self.WIDTH - filled)
        elapsed = time.monotonic() - self.start
        self.stream.write(f"\r[{bar}] {100 * frac:5.1f}%  t = {t:.4g} s  ({elapsed:.1f} s)")
        self.stream.flush()

    def close(self) -> None:
        self.stream.write("\n")
        self.stream.flush()


def summary(res: SimulationResult) -> str:
    """One line: status, outputs, steps, energy balance drift, smallest singularity measure."""
    st = res.stats
    t_last = f"{res.t[-1]:.6g}" if len(res.t) else "-"
    min_sigma = st.get("min_sigma", math.inf)
    return (
        f"{res.status}: {len(res.t)} outputs to t = {t_last} s, {st.get('naccept', 0)} steps "
        f"({st.get('nreject', 0)} rejected, {st.get('nfev', 0)} evaluations), "
        f"energy drift {res.energy.drift:.3g} J, min sigma {min_sigma:.3g}"
    )


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="planardyn",
        description="Dynamics of planar closed-chain mechanisms from model files.",
        epilog="Exit status: 0 ok, 1 the simulation stopped early, 2 usage or model error.",
    )
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    s = sub.add_parser("simulate", help="simulate a model file and write the trajectory as CSV")
    s.add_argument("model", type=Path, help="model file (.yaml, .yml or .json)")
    s.add_argument("--t-end", type=float, help="end time (s); default: the model's, else 1")
    s.add_argument("--method", help="dop853 (default), dopri5, radau5 or rk4 (needs --dt)")
    s.add_argument("--rtol", type=float, help="relative tolerance (default 1e-9)")
    s.add_argument("--atol", type=float, help="absolute tolerance (default 1e-12)")
    s.add_argument("--dt", type=float, help="fixed step (s): for rk4, or to switch error control off")
    s.add_argument("--output-dt", type=float, help="spacing of the output rows (s); default: the model's, else every step")
    s.add_argument("--max-steps", type=int, help="most step attempts before giving up")
    s.add_argument("-o", "--output", type=Path, help="CSV file to write (columns t, q, qd_*, qdd_*, tau_*, energies, sigma)")
    s.add_argument("--progress", action="store_true", help="show a progress bar on stderr even when it is not a terminal")
    s.add_argument("--no-progress", action="store_true", help="never show the progress bar")

    d = sub.add_parser("demo", help="simulate the shipped five-bar robot and write PNG plots")
    d.add_argument("--out", type=Path, default=Path("out/demo"), help="output folder (default out/demo)")
    d.add_argument("--model", type=Path, default=DEMO_MODEL, help="model file (default: examples/models/five-bar.yaml)")
    return p


def _simulate(args: argparse.Namespace) -> int:
    mech = load(args.model)
    t_end = args.t_end if args.t_end is not None else (mech.simulate_defaults.get("t_end") or 1.0)
    show = not args.no_progress and (args.progress or sys.stderr.isatty())
    bar = ProgressBar(t_end) if show else None
    try:
        res = mech.simulate(
            t_end=args.t_end,
            method=args.method,
            rtol=args.rtol,
            atol=args.atol,
            dt=args.dt,
            output_dt=args.output_dt,
            max_steps=args.max_steps,
            progress=bar,
        )
        if bar is not None and res.success:
            bar(t_end)
    finally:
        if bar is not None:
            bar.close()
    if args.output is not None:
        args.output.parent.mkdir(parents=True, exist_ok=True)
        res.to_csv(args.output)
    line = summary(res) + (f" -> {args.output}" if args.output is not None else "")
    print(line)
    if not res.success:
        print(f"planardyn: simulation stopped early: {res.message}", file=sys.stderr)
        return EXIT_FAILED
    return EXIT_OK


def _demo(args: argparse.Namespace) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from .plot import draw_mechanism, plot_coordinates, plot_efforts, plot_energy

    if not args.model.is_file():
        raise FileNotFoundError(f"{args.model}: the demo model is not there (pass --model MODEL)")
    mech = load(args.model)
    res = mech.simulate()
    print(summary(res))
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    written = []

    def save(fig, name: str) -> None:
        fig.tight_layout()
        fig.savefig(out / name, dpi=120)
        plt.close(fig)
        written.append(out / name)

    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    plot_coordinates(res, ax=axes[0])
    plot_coordinates(res, ax=axes[1], which="qd")
    axes[0].set_title(f"{mech.name}: coordinates")
    save(fig, "coordinates.png")

    fig, ax = plt.subplots(figsize=(8, 4))
    plot_efforts(res, ax=ax)
    ax.set_title("drive efforts")
    save(fig, "efforts.png")

    fig, ax = plt.subplots(figsize=(8, 4.5))
    plot_energy(res, ax=ax)
    ax.set_title(f"energy (balance drift {res.energy.drift:.2g} J)")
    save(fig, "energy.png")

    n_snap = 4
    idx = np.linspace(0, len(res.t) - 1, n_snap).round().astype(int) if len(res.t) else []
    fig, axes = plt.subplots(1, n_snap, figsize=(4 * n_snap, 4))
    pts = mech.point_positions(res.x)  # (N, P, 2): one frame for every snapshot
    lo, hi = np.nanmin(pts, axis=(0, 1)), np.nanmax(pts, axis=(0, 1))
    pad = 0.1 * mech.scale
    for ax, k in zip(np.atleast_1d(axes), idx):
        draw_mechanism(mech, res.x[k], ax=ax, labels=True)
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - 2 * pad, hi[1] + pad)
        ax.set_title(f"t = {res.t[k]:.3g} s")
    save(fig, "mechanism.png")

    res.to_csv(out / "results.csv")
    written.append(out / "results.csv")
    print("wrote " + ", ".join(str(p) for p in written))
    return EXIT_OK if res.success else EXIT_FAILED


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    try:
        if args.command == "simulate":
            return _simulate(args)
        return _demo(args)
    except (AssemblyError, SingularityError) as e:
        # The start state could not be computed: the computation failed.
        print(f"planardyn: {e}", file=sys.stderr)
        return EXIT_FAILED
    except (PlanardynError, ValueError, OSError) as e:
        print(f"planardyn: {e}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("planardyn: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
