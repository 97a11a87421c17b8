"""Does the accuracy follow the tolerance everywhere? The energy drift of shipped models over a
dense sweep of tolerances, rtol = atol = 10^(-k/PER_DECADE), 1 s each, and the tolerances whose
drift stands out: over FACTOR times the geometric mean of its neighbours' (k - 1 and k + 1),
an isolated failure of the error estimate rather than the tolerance's own level. Prints, per
model and method, the outliers (worst first), the runs over --over J, the worst drift and the
evaluations of the sweep (its cost).

    .venv/bin/python benchmarks/drift_outliers.py                          # 11 models, k = 20..200
    .venv/bin/python benchmarks/drift_outliers.py --model five-bar-free-fall --method dopri5 \\
        --per-decade 150 --k 600 1350 --over 1e-4                          # the five-bar's band

The figures in the comments of `integrate/dop853.rs` (REACH_E3), `simulate/run.rs` (the type II
fall's decision) and tests/estimate_reach.rs come from it (--json keeps every run).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time

import numpy as np
import planardyn as pdy

#: The models of the sweeps quoted in the code (the shipped examples that run 1 s without
#: inputs; five-bar-compliant left out: its stiff drives need radau5).
MODELS = ["3-rrr", "andrews-squeezer", "five-bar", "five-bar-free-fall", "five-bar-robot", "four-bar-gravity",
          "gear-train", "geared-five-bar", "hydraulic-boom", "scotch-yoke", "slider-crank"]


def sweep(name: str, method: str, ks: range, per_decade: float) -> list[tuple[int, float, float, int]]:
    """(k, rtol, max |energy balance| J, evaluations) of each run; the drift is NaN where the run
    failed."""
    mech = pdy.load_example(name)
    rows = []
    for k in ks:
        r = 10 ** (-k / per_decade)
        res = mech.simulate(t_end=1.0, method=method, rtol=r, atol=r)
        drift = float(np.nanmax(np.abs(res.energy.balance))) if res.success else math.nan
        rows.append((k, r, drift, int(res.stats["nfev"])))
    return rows


def outliers(rows: list[tuple[int, float, float, int]], factor: float) -> list[tuple[float, int, float, float]]:
    """(ratio, k, rtol, drift) of each run over ``factor`` times its neighbours' geometric mean,
    the largest ratio first."""
    found = []
    for (_, _, a, _), (k, r, b, _), (_, _, c, _) in zip(rows, rows[1:], rows[2:]):
        if b > 0 and all(math.isfinite(v) for v in (a, b, c)):
            ratio = b / max(math.sqrt(max(a, 1e-300) * max(c, 1e-300)), 1e-300)
            if ratio > factor:
                found.append((ratio, k, r, b))
    return sorted(found, reverse=True)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", nargs="+", default=MODELS)
    ap.add_argument("--method", nargs="+", default=["dopri5", "dop853"])
    ap.add_argument("--k", nargs=2, type=int, default=[20, 200], metavar=("FIRST", "LAST"))
    ap.add_argument("--per-decade", type=float, default=20.0)
    ap.add_argument("--factor", type=float, default=10.0)
    ap.add_argument("--over", type=float, default=None, help="also count the runs whose drift is over this (J)")
    ap.add_argument("--json", help="write every run's (k, rtol, drift, nfev) here")
    args = ap.parse_args(argv)
    ks = range(args.k[0], args.k[1] + 1)
    kept: dict[str, list[tuple[int, float, float, int]]] = {}
    for name in args.model:
        for method in args.method:
            start = time.perf_counter()
            rows = kept[f"{name}/{method}"] = sweep(name, method, ks, args.per_decade)
            found = outliers(rows, args.factor)
            drifts = np.array([row[2] for row in rows])
            failed = int(np.isnan(drifts).sum())
            line = f"{name} {method}: {len(found)} over {args.factor:g}x, "
            if failed < len(rows):
                worst = int(np.nanargmax(drifts))
                line += f"worst drift {drifts[worst]:.3g} J at rtol {rows[worst][1]:.3g}, "
            line += f"{sum(row[3] for row in rows)} evaluations"
            if args.over is not None:
                line += f", {int((drifts > args.over).sum())} of {len(rows)} over {args.over:g} J"
            print(line + (f", {failed} failed" if failed else "") + f" ({time.perf_counter() - start:.0f} s)",
                  flush=True)
            for ratio, k, r, drift in found:
                print(f"    k = {k} rtol {r:.3g}: {drift:.3g} J, {ratio:.0f}x its neighbours'")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(kept, f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
