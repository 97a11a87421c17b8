"""The dense output's error over a sweep of tolerances, against a reference run at rtol 1e-13,
on the steps in the user's chart and on those in other charts (partition or alternative
charts, where sol is the polynomial through the chart's assembled points: docs/api.md).

For each run (rtol = 10^(-k/50), atol = --atol-ratio x rtol) and each kind of step, the largest over q and qd of
  sol-out: |sol(t) - output(t)| / (atol + rtol |output|) at the outputs (the docs' claim),
  sol-ref: |sol(t) - ref(t)| / (atol + rtol |ref|) at the outputs and between them,
  out-ref: |output(t) - ref(t)| / (atol + rtol |ref|) at the outputs,
so that sol-ref / out-ref says how much the dense output adds to the run's own error. Near a
zero of a rate the tolerance is atol alone: there sol-ref / out-ref reached 2.7 at atol 1e-3
rtol, at a midpoint nearer the zero than the outputs (per column at atol + rtol max|value|
the two agree to 0.1 %). The other charts' rows are the result's `partitioned` ones; the
alternative charts' alone were measured with `Trajectory::record` flagging `Chart::Pairs`
only (s23-mend's note).

    .venv/bin/python benchmarks/dense_sweep.py [--model five-bar-free-fall] [--k 150 500 10] [--atol-ratio 1e-3]
"""

from __future__ import annotations

import argparse

import numpy as np
import planardyn as pd

REF_RTOL = 1e-13


def ratios(a: np.ndarray, b: np.ndarray, rtol: float, atol: float) -> np.ndarray:
    """|a - b| / (atol + rtol |b|), largest over the columns, per row."""
    return np.max(np.abs(a - b) / (atol + rtol * np.abs(b)), axis=1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", default="five-bar-free-fall")
    ap.add_argument("--methods", nargs="+", default=["dopri5", "dop853"])
    ap.add_argument("--k", nargs=3, type=int, default=[150, 500, 10], metavar=("FROM", "TO", "BY"))
    ap.add_argument("--t-end", type=float, default=1.0)
    ap.add_argument("--output-dt", type=float, default=2e-4)
    ap.add_argument("--atol-ratio", type=float, default=1.0, help="atol = this x rtol")
    args = ap.parse_args()
    mech = pd.load_example(args.model)
    dt = args.output_dt
    n = int(round(args.t_end / dt))
    t_out = np.linspace(0.0, args.t_end, n + 1)
    t_mid = (t_out[:-1] + t_out[1:]) / 2
    print(f"{args.model}, t_end {args.t_end} s, outputs every {dt:g} s; columns per kind of step: "
          f"rows, sol-out, sol-ref, out-ref (fractions of the run's tolerance; atol {args.atol_ratio:g} rtol)")
    for method in args.methods:
        ref = mech.simulate(t_end=args.t_end, method=method, rtol=REF_RTOL, atol=REF_RTOL, t_eval=t_out,
                            dense_output=True)
        assert ref.success, ref.message
        rq, rqd = ref.q, ref.qd
        mq, mqd = ref.sol(t_mid)
        for k in range(args.k[0], args.k[1] + 1, args.k[2]):
            tol = 10 ** (-k / 50)
            atol = args.atol_ratio * tol
            res = mech.simulate(t_end=args.t_end, method=method, rtol=tol, atol=atol, t_eval=t_out, dense_output=True)
            if not res.success:
                print(f"{method} rtol {tol:.3g}: {res.status} {res.message}")
                continue
            q, qd = res.sol(t_out)
            sq, sqd = res.sol(t_mid)
            sol_out = np.maximum(ratios(q, res.q, tol, atol), ratios(qd, res.qd, tol, atol))
            sol_ref = np.maximum(ratios(q, rq, tol, atol), ratios(qd, rqd, tol, atol))
            mid_ref = np.maximum(ratios(sq, mq, tol, atol), ratios(sqd, mqd, tol, atol))
            out_ref = np.maximum(ratios(res.q, rq, tol, atol), ratios(res.qd, rqd, tol, atol))
            other = np.asarray(res.partitioned, dtype=bool)
            # A midpoint is in another chart's step when both outputs around it are.
            other_mid = other[:-1] & other[1:]
            user_mid = ~other[:-1] & ~other[1:]
            st = res.stats
            cells = []
            for rows, mids in ((~other, user_mid), (other, other_mid)):
                if not rows.any():
                    cells.append(f"{0:>5}      -        -        -    ")
                    continue
                sr = max(sol_ref[rows].max(), mid_ref[mids].max() if mids.any() else 0.0)
                cells.append(f"{rows.sum():>5} {sol_out[rows].max():8.3g} {sr:8.3g} {out_ref[rows].max():8.3g}")
            print(f"{method:6} k {k:3} rtol {tol:8.3g}  steps {st['naccept']:4} (partition {st['partition_steps']:3}, "
                  f"alt {st['alt_steps']:3})  user: {cells[0]}  other: {cells[1]}", flush=True)


if __name__ == "__main__":
    main()
