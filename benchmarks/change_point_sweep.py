"""Random sweeps through change points and type II passages (1 s passive from rest under gravity).

  python benchmarks/change_point_sweep.py parallelogram --drawings 20 --seed 1
  python benchmarks/change_point_sweep.py five-bar --drawings 100 --seed 1

parallelogram: planardyn.library.double_parallelogram with crank in [0.1, 0.5] m, spacing in
[0.2, 0.8] m, theta uniform in (-pi, pi); five-bar: the drawings of tests/test_loader_fuzz.py's
`five_bars`. Each drawing runs with DOP853 and DOPRI5 at each rtol (atol = 1e-2 rtol); a run
counts as failed unless it succeeds and, at rtol <= 1e-11, its energy drift is within 1e-8 of
the peak kinetic energy. Prints one line per failure and the counts.
"""

from __future__ import annotations

import argparse
import math
import random
from typing import Any

import numpy as np
from planardyn import from_dict
from planardyn import library as lib

BALANCE = 1e-8  # energy drift per peak kinetic energy at rtol <= 1e-11 (the fuzz test's bound)


def parallelogram(rng: random.Random) -> dict[str, Any]:
    return dict(crank=rng.uniform(0.1, 0.5), spacing=rng.uniform(0.2, 0.8), theta=rng.uniform(-math.pi, math.pi))


def five_bar(rng: random.Random) -> dict[str, Any]:
    base, proximal = rng.uniform(0.1, 0.3), rng.uniform(0.15, 0.3)
    th1, th2 = rng.uniform(math.pi / 2, math.pi), rng.uniform(0.0, math.pi / 2)
    b1 = np.array([-base / 2 + proximal * math.cos(th1), proximal * math.sin(th1)])
    b2 = np.array([base / 2 + proximal * math.cos(th2), proximal * math.sin(th2)])
    distal = float(np.linalg.norm(b2 - b1)) / 2 * rng.uniform(1.2, 2.0)
    return dict(base=base, proximal=proximal, distal=distal, theta1=th1, theta2=th2, mode=rng.choice([1, -1]))


KINDS = {"parallelogram": (parallelogram, lib.double_parallelogram_model), "five-bar": (five_bar, lib.five_bar_model)}


def run(model: dict[str, Any], method: str, rtol: float) -> str | None:
    """None if the run passes, else why not."""
    res = from_dict(model).simulate(t_end=1.0, method=method, rtol=rtol, atol=1e-2 * rtol)
    if not res.success:
        return res.message
    if rtol <= 1e-11:
        peak = res.energy.kinetic.max()
        if abs(res.energy.drift) > BALANCE * peak:
            return f"energy drift {res.energy.drift:.2e} J, {abs(res.energy.drift) / peak:.2e} of the peak"
    return None


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("kind", choices=sorted(KINDS))
    ap.add_argument("--drawings", type=int, default=20)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--rtols", type=float, nargs="+", default=[1e-6, 1e-9, 1e-11])
    ap.add_argument("--methods", nargs="+", default=["dop853", "dopri5"])
    ap.add_argument("--dims", help="one drawing's dimensions as a Python dict literal (instead of random)")
    args = ap.parse_args()
    draw, model = KINDS[args.kind]
    rng = random.Random(args.seed)
    drawings = [eval(args.dims)] if args.dims else [draw(rng) for _ in range(args.drawings)]  # noqa: S307
    runs = failed = 0
    bad = set()
    for k, dims in enumerate(drawings):
        for method in args.methods:
            for rtol in args.rtols:
                runs += 1
                why = run(model(**dims), method, rtol)
                if why is not None:
                    failed += 1
                    bad.add(k)
                    print(f"FAIL #{k} {dims} {method} rtol {rtol:g}: {why}", flush=True)
    print(f"{args.kind}: {failed} of {runs} runs failed, {len(bad)} of {len(drawings)} drawings")


if __name__ == "__main__":
    main()
