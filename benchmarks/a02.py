"""IFToMM A02, the N-four-bar, through its change points: error against the exact
one-coordinate reduction (angle and rate, at every output), crossings found against those of
the reduction, counters and time, per N and tolerance.

    .venv/bin/python benchmarks/a02.py [--n 2 5 10 20 40] [--t-end 20] [--rtol 1e-12 ...]
                                       [--atol-ratio 1e-2 ...] [--repeat 3]

The reduction (every rod at the same angle theta, couplers translating, uniform 1 kg bars of
1 m): ((N + 1)/3 + N) theta'' = -g cos(theta) ((N + 1)/2 + N), by scipy's DOP853 at rtol 1e-13.
Its crossings are where theta passes a multiple of pi. Outputs every 10 ms; each rtol is run
with atol = rtol x each atol-ratio; time is the best of `--repeat` runs, CPU time of this process.
"""

from __future__ import annotations

import argparse
import itertools
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parent))

import planardyn as pd  # noqa: E402
from families import G, a02  # noqa: E402


def reduction(n: int, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """theta (rad) and theta' (rad/s) of the reduction at the times t (from 0, increasing)."""
    k = G * ((n + 1) / 2 + n) / ((n + 1) / 3 + n)
    sol = solve_ivp(lambda _, y: [y[1], -k * math.cos(y[0])], (0.0, t[-1]), [math.pi / 2, -1.0],
                    method="DOP853", rtol=1e-13, atol=1e-14, t_eval=t)
    return sol.y[0], sol.y[1]


def crossings(theta: np.ndarray) -> int:
    """Multiples of pi that theta passes between its samples (one per change point)."""
    k = np.floor(theta / math.pi)
    return int(np.abs(np.diff(k)).sum())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[2, 5, 10, 20, 40])
    ap.add_argument("--t-end", type=float, default=20.0)
    ap.add_argument("--rtol", type=float, nargs="+", default=[1e-12])
    ap.add_argument("--atol-ratio", type=float, nargs="+", default=[1e-2], help="atol = rtol x each of these")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    t = np.linspace(0.0, args.t_end, int(round(args.t_end / 0.01)) + 1)
    print("| N | rtol | atol | status | angle error (rad) | rate error (rad/s) | crossings | rank drop "
          "| nfev | rejected | CPU time (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for n in args.n:
        mech = pd.from_dict(a02(n))
        theta, rate = reduction(n, t)
        expected = crossings(theta)
        for rtol, ratio in itertools.product(args.rtol, args.atol_ratio):
            atol = rtol * ratio
            best, res = math.inf, None
            for _ in range(args.repeat):
                start = time.process_time()
                res = mech.simulate(t_end=args.t_end, t_eval=t, method="dop853", rtol=rtol, atol=atol)
                best = min(best, time.process_time() - start)
            assert res is not None
            k = len(res.t)
            err = np.abs(res.q[:, 0] - theta[:k]).max()
            err_rate = np.abs(res.qd[:, 0] - rate[:k]).max()
            ranks = sorted({c.rank_drop for c in res.change_points})
            print(f"| {n} | {rtol:.0e} | {atol:.0e} | {res.status} | {err:.1e} | {err_rate:.1e} | "
                  f"{len(res.change_points)}/{expected} | {', '.join(map(str, ranks))} | {res.stats['nfev']} | "
                  f"{res.stats['nreject']} | {best:.3f} |", flush=True)


if __name__ == "__main__":
    main()
