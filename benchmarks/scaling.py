"""Cost against size: build and simulate the families of benchmarks/families.py for N = 1 ... 80
and print, per N, the wall time of building the model (``planardyn.from_dict``, best of
``--build-repeats``), per right-hand-side evaluation (as the integrator makes it, monitor
included) and per simulated second, the integrator's counters, and the fitted log-log exponent
of each cost against the number of bodies.

    .venv/bin/python benchmarks/scaling.py                      # parallelograms, five-bars, ladder
    .venv/bin/python benchmarks/scaling.py --family a02 --n 2 5 10 20 --t-end 0.5
    .venv/bin/python benchmarks/scaling.py --budget 60          # skip larger N once a run takes > 60 s
    .venv/bin/python benchmarks/scaling.py --build-only --n 10 20 40 80   # the build alone, no runs

The parallelogram chain has the same one-coordinate motion for every N (a simple pendulum of
1 m, families.py): each run is checked against its closed-form period.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import planardyn  # noqa: E402
from families import FAMILIES, parallelograms, pendulum_period  # noqa: E402

THETA0 = math.radians(30)
DEFAULT_N = [1, 2, 5, 10, 20, 40, 80]


def build(spec: dict[str, Any], repeats: int) -> tuple[planardyn.Mechanism, float]:
    """The model and the best wall time (s) of building it `repeats` times."""
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        mech = planardyn.from_dict(spec)
        best = min(best, time.perf_counter() - start)
    return mech, best


def run(family: str, n: int, t_end: float, rtol: float, atol: float, repeats: int, build_only: bool) -> dict[str, Any]:
    spec = parallelograms(n, THETA0) if family == "parallelograms" else FAMILIES[family](n)
    mech, build_wall = build(spec, repeats)
    if build_only:
        return {"N": n, "bodies": len(spec["bodies"]), "build": build_wall}
    # Every step is an output (a stopped run's last row is where it stopped), except for the
    # parallelograms: the start, one closed-form period and the end.
    period = pendulum_period(THETA0)
    times = [0.0, period, t_end] if family == "parallelograms" and period < t_end else None
    start = time.perf_counter()
    res = mech.simulate(t_end=t_end, rtol=rtol, atol=atol, t_eval=times)
    wall = time.perf_counter() - start
    st = res.stats
    row = {
        "N": n,
        "bodies": len(spec["bodies"]),
        "status": res.status,
        "build": build_wall,
        "t": float(res.t[-1]),
        "wall": wall,
        "nfev": st["nfev"],
        "steps": st["naccept"],
        "rejected": st["nreject"],
        "refused": st.get("failed_evaluations", 0),
        "switches": st.get("chart_switches", 0),
        "min_sigma": st.get("min_sigma", float("nan")),
        "err": float("nan"),
    }
    if family == "parallelograms" and len(res.t) == 3:
        row["err"] = abs(float(res.q[1, 0]) - (-math.pi / 2 + THETA0))
    return row


def slope(x: list[float], y: list[float]) -> float:
    """Least-squares slope of log y against log x."""
    return float(np.polyfit(np.log(x), np.log(y), 1)[0]) if len(x) > 1 else float("nan")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--family", nargs="+", default=["parallelograms", "five-bars", "ladder"], choices=list(FAMILIES))
    ap.add_argument("--n", nargs="+", type=int, default=DEFAULT_N)
    ap.add_argument("--t-end", type=float, default=3.0, help="simulated time (s)")
    ap.add_argument("--rtol", type=float, default=1e-9)
    ap.add_argument("--atol", type=float, default=1e-12)
    ap.add_argument("--build-repeats", type=int, default=3, help="builds per N, the best is kept")
    ap.add_argument("--budget", type=float, default=120.0, help="skip larger N after a run longer than this (s)")
    ap.add_argument("--build-only", action="store_true", help="time the build alone (no simulation)")
    args = ap.parse_args()
    if args.build_only:
        build_table(args)
        return
    for family in args.family:
        print(f"\n{family}: t_end {args.t_end} s, rtol {args.rtol:g}, atol {args.atol:g}")
        head = "| N | bodies | status | t reached (s) | build (ms) | wall (s) | per eval (us) | per sim. s (ms) | nfev | steps | rejected | refused | switches | min sigma | period err (rad) |"
        print(head)
        print("|" + "---|" * (head.count("|") - 1))
        rows = []
        for n in sorted(args.n):
            r = run(family, n, args.t_end, args.rtol, args.atol, args.build_repeats, False)
            r["per_eval"] = r["wall"] / max(r["nfev"], 1) * 1e6
            r["per_s"] = r["wall"] / max(r["t"], 1e-12) * 1e3
            rows.append(r)
            print(
                f"| {r['N']} | {r['bodies']} | {r['status']} | {r['t']:.3g} | {r['build'] * 1e3:.3g} | {r['wall']:.3g} | {r['per_eval']:.3g} "
                f"| {r['per_s']:.3g} | {r['nfev']} | {r['steps']} | {r['rejected']} | {r['refused']} "
                f"| {r['switches']} | {r['min_sigma']:.2g} | {r['err']:.1e} |",
                flush=True,
            )
            if r["wall"] > args.budget:
                print(f"(larger N skipped: {r['wall']:.0f} s > --budget {args.budget:g} s)")
                break
        big = [r for r in rows if r["bodies"] >= 10] or rows
        b = [r["bodies"] for r in big]
        print(
            f"exponent (bodies >= 10): per evaluation {slope(b, [r['per_eval'] for r in big]):.2f}, "
            f"per simulated second {slope(b, [r['per_s'] for r in big]):.2f}, "
            f"build {slope(b, [r['build'] for r in big]):.2f}"
        )


def build_table(args: argparse.Namespace) -> None:
    """The build's wall time (best of ``--build-repeats``) per family and N, and its exponent."""
    for family in args.family:
        print(f"\n{family}: build only, best of {args.build_repeats}")
        print("| N | bodies | build (ms) |\n|---|---|---|")
        rows = [run(family, n, 0.0, 0.0, 0.0, args.build_repeats, True) for n in sorted(args.n)]
        for r in rows:
            print(f"| {r['N']} | {r['bodies']} | {r['build'] * 1e3:.3g} |", flush=True)
        big = [r for r in rows if r["bodies"] >= 10] or rows
        print(f"exponent (bodies >= 10): build {slope([r['bodies'] for r in big], [r['build'] for r in big]):.2f}")


if __name__ == "__main__":
    main()
