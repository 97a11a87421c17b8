"""IFToMM A02, the N-four-bar, through its change points: error against the exact
one-coordinate reduction, crossings, counters and time, per N.

    .venv/bin/python benchmarks/a02.py [--n 2 5 10 20 40] [--t-end 20] [--rtol 1e-12]

The reduction (every rod at the same angle theta, couplers translating, uniform 1 kg bars of
1 m): ((N + 1)/3 + N) theta'' = -g cos(theta) ((N + 1)/2 + N), by scipy's DOP853 at rtol 1e-13.
Outputs every 10 ms; time is the best of three runs, CPU time of this process.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parent))

import planardyn as pd  # noqa: E402
from families import G, a02  # noqa: E402


def reduction(n: int, t: np.ndarray) -> np.ndarray:
    k = G * ((n + 1) / 2 + n) / ((n + 1) / 3 + n)
    sol = solve_ivp(lambda _, y: [y[1], -k * math.cos(y[0])], (0.0, t[-1]), [math.pi / 2, -1.0],
                    method="DOP853", rtol=1e-13, atol=1e-14, t_eval=t)
    return sol.y[0]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[2, 5, 10, 20, 40])
    ap.add_argument("--t-end", type=float, default=20.0)
    ap.add_argument("--rtol", type=float, default=1e-12)
    args = ap.parse_args()
    t = np.linspace(0.0, args.t_end, int(round(args.t_end / 0.01)) + 1)
    print("| N | bodies | status | max error (rad) | crossings | rank drop | nfev | rejected | CPU time (s) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for n in args.n:
        mech = pd.from_dict(a02(n))
        best, res = math.inf, None
        for _ in range(3):
            start = time.process_time()
            res = mech.simulate(t_end=args.t_end, t_eval=t, method="dop853", rtol=args.rtol, atol=args.rtol * 1e-2)
            best = min(best, time.process_time() - start)
        assert res is not None
        err = np.abs(res.q[:, 0] - reduction(n, res.t)).max()
        ranks = sorted({c.rank_drop for c in res.change_points})
        print(f"| {n} | {2 * n + 1} | {res.status} | {err:.1e} | {len(res.change_points)} | "
              f"{', '.join(map(str, ranks))} | {res.stats['nfev']} | {res.stats['nreject']} | {best:.3f} |")


if __name__ == "__main__":
    main()
