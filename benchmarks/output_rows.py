"""Rows on the output grid against the steps: the energy drift of a run's rows on a 0.01 s grid
and of the same run's rows at every accepted step, per method and tolerance (issue 23's
promise: an output is as accurate as the integrated steps).

    .venv/bin/python benchmarks/output_rows.py [--model five-bar-free-fall] [--t-end 1]
                                               [--methods dop853 dopri5] [--output-dt 0.01]

rtol = atol over 21 log-spaced values 1e-4 ... 1e-8. Each line: method, rtol, the grid run's
energy drift (J, max |T + V - W - E0| over its rows) and evaluations, the every-step run's, and
their ratio (rows / steps).
"""

from __future__ import annotations

import argparse

import numpy as np
import planardyn as pd

#: rtol = atol = 10^(-4 - k / 5), k = 0..20: the benchmarks' sweep (5 per decade).
TOLERANCES = np.logspace(-4, -8, 21)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="five-bar-free-fall")
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--methods", nargs="+", default=["dop853", "dopri5"])
    parser.add_argument("--output-dt", type=float, default=0.01)
    args = parser.parse_args()
    mech = pd.load_example(args.model)
    print("method rtol rows_drift_J rows_nfev steps_drift_J steps_nfev ratio")
    for method in args.methods:
        for rtol in TOLERANCES:
            run = {"method": method, "rtol": rtol, "atol": rtol}
            rows = mech.simulate(args.t_end, output_dt=args.output_dt, **run)
            steps = mech.simulate(args.t_end, **run)
            d_rows, d_steps = rows.stats["energy_drift"], steps.stats["energy_drift"]
            print(
                f"{method} {rtol:.3g} {d_rows:.3e} {rows.stats['nfev']} {d_steps:.3e} {steps.stats['nfev']} "
                f"{d_rows / d_steps:.2f}"
            )


if __name__ == "__main__":
    main()
