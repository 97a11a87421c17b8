"""Speed-up of planardyn.batch.simulate on native threads: 64 five-bar runs of 1 s each
(start angles spread around the drawing), on 1 thread and on 2, best of 3 each.

    .venv/bin/python benchmarks/batch_scaling.py [--threads 1 2 4] [--n 64]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np
import planardyn as pd
from planardyn.batch import simulate

MODEL = Path(__file__).resolve().parents[1] / "examples" / "models" / "five-bar.yaml"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--n", type=int, default=64)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    mech = pd.load(MODEL)
    variants = [(mech, {"q0": mech.q0 + 0.002 * k * np.array([1.0, -1.0])}) for k in range(a.n)]
    print(f"{a.n} five-bar simulations of 1 s (DOP853, rtol 1e-9), {os.cpu_count()} cores")
    base = None
    for n in a.threads:
        best = min(_timed(variants, n) for _ in range(a.repeat))
        base = base or best
        print(f"  {n:2d} thread(s): {best:7.3f} s   speed-up {base / best:5.2f}   efficiency {base / best / n:5.1%}")


def _timed(variants, threads: int) -> float:
    t0 = time.perf_counter()
    out = simulate(variants, 1.0, threads=threads)
    dt = time.perf_counter() - t0
    assert all(r.success for r in out), [str(r) for r in out if not r.success][:3]
    return dt


if __name__ == "__main__":
    main()
