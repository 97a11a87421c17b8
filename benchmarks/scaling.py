"""Cost against size: build and simulate the families of benchmarks/families.py for N = 1 ... 80
and print, per N, the wall time of building the model (``planardyn.from_dict``, best of
``--build-repeats``), per right-hand-side evaluation (as the integrator makes it, monitor
included) and per simulated second (wall, and the CPU time of the calling thread, which a
loaded machine's waiting does not count), the integrator's counters, and the fitted log-log
exponent of each cost against the number of bodies.

    .venv/bin/python benchmarks/scaling.py                      # parallelograms, five-bars, ladder
    .venv/bin/python benchmarks/scaling.py --family a02 --n 2 5 10 20 --t-end 0.5
    .venv/bin/python benchmarks/scaling.py --budget 60          # skip larger N once a run takes > 60 s
    .venv/bin/python benchmarks/scaling.py --build-only --n 10 20 40 80   # the build alone, no runs
    .venv/bin/python benchmarks/scaling.py --icount --n 10 20 40 80       # also in instructions

With ``--icount`` the same three costs also in instructions, which the machine's load does not
change (valgrind's callgrind, deterministic): one build is the count of a process building the
model twice less one building it once; one run is the count of a process building and
simulating less one building; per evaluation and per simulated second are that run's count over
its evaluations and its simulated time. Python's hashing is seeded and numpy's BLAS kept on one
thread (``ICOUNT_ENV``) so that the two processes differ by the counted work alone.

The parallelogram chain has the same one-coordinate motion for every N (a simple pendulum of
1 m, families.py): each run is checked against its closed-form period.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
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
#: Fixed hash seed and one BLAS thread in the processes callgrind counts (numpy's idle OpenBLAS
#: workers spin, and valgrind counts them: benchmarks/small_runs.py).
ICOUNT_ENV = {"PYTHONHASHSEED": "0", "OPENBLAS_NUM_THREADS": "1"}


def model(family: str, n: int) -> dict[str, Any]:
    """The family's model dict at size n."""
    return parallelograms(n, THETA0) if family == "parallelograms" else FAMILIES[family](n)


def build(spec: dict[str, Any], repeats: int) -> tuple[planardyn.Mechanism, float]:
    """The model and the best wall time (s) of building it `repeats` times."""
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        mech = planardyn.from_dict(spec)
        best = min(best, time.perf_counter() - start)
    return mech, best


def simulate(mech: planardyn.Mechanism, family: str, t_end: float, rtol: float, atol: float) -> Any:
    """One run as the tables time it: every step an output (a stopped run's last row is where it
    stopped), except for the parallelograms: the start, one closed-form period and the end."""
    period = pendulum_period(THETA0)
    times = [0.0, period, t_end] if family == "parallelograms" and period < t_end else None
    return mech.simulate(t_end=t_end, rtol=rtol, atol=atol, t_eval=times)


def run(family: str, n: int, t_end: float, rtol: float, atol: float, repeats: int, build_only: bool) -> dict[str, Any]:
    spec = model(family, n)
    mech, build_wall = build(spec, repeats)
    if build_only:
        return {"N": n, "bodies": len(spec["bodies"]), "build": build_wall}
    start, cpu = time.perf_counter(), time.thread_time()
    res = simulate(mech, family, t_end, rtol, atol)
    cpu = time.thread_time() - cpu
    wall = time.perf_counter() - start
    st = res.stats
    row = {
        "N": n,
        "bodies": len(spec["bodies"]),
        "status": res.status,
        "build": build_wall,
        "t": float(res.t[-1]),
        "wall": wall,
        "cpu": cpu,
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


def icount_child(what: str, family: str, n: int, t_end: float, rtol: float, atol: float) -> None:
    """The process callgrind counts: ``build1``/``build2`` build the model once/twice, ``run``
    builds it once and simulates it, printing the run's evaluations and simulated time."""
    spec = model(family, n)
    for _ in range(2 if what == "build2" else 1):
        mech = planardyn.from_dict(spec)
    if what == "run":
        res = simulate(mech, family, t_end, rtol, atol)
        print(json.dumps({"nfev": res.stats["nfev"], "t": float(res.t[-1])}))


def counted(what: str, family: str, n: int, args: argparse.Namespace) -> tuple[int, str]:
    """Instructions callgrind counts in one `icount_child` process, and what it printed."""
    command = [
        sys.executable,
        __file__,
        "--icount-child",
        what,
        "--family",
        family,
        "--n",
        str(n),
        "--t-end",
        repr(args.t_end),
        "--rtol",
        repr(args.rtol),
        "--atol",
        repr(args.atol),
    ]
    out = subprocess.run(
        ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", *command],
        capture_output=True,
        text=True,
        check=True,
        env={**os.environ, **ICOUNT_ENV},
    )
    return int(re.search(r"Collected : (\d+)", out.stderr).group(1)), out.stdout  # type: ignore[union-attr]


def instructions(family: str, n: int, args: argparse.Namespace, build_only: bool) -> dict[str, float]:
    """Instructions of one build and, unless `build_only`, of one run, per evaluation and per
    simulated second (the module's doc says how)."""
    once = counted("build1", family, n, args)[0]
    out = {"build": counted("build2", family, n, args)[0] - once}
    if not build_only:
        total, printed = counted("run", family, n, args)
        facts = json.loads(printed)
        out["run"] = total - once
        out["per_eval"] = out["run"] / max(facts["nfev"], 1)
        out["per_s"] = out["run"] / max(facts["t"], 1e-12)
    return out


def slope(x: list[float], y: list[float]) -> float:
    """Least-squares slope of log y against log x."""
    return float(np.polyfit(np.log(x), np.log(y), 1)[0]) if len(x) > 1 else float("nan")


def fitted(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The rows the exponents are fitted over: 10 bodies and more (all if none has)."""
    return [r for r in rows if r["bodies"] >= 10] or rows


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
    ap.add_argument("--icount", action="store_true", help="also count instructions (valgrind's callgrind)")
    ap.add_argument("--icount-child", choices=["build1", "build2", "run"], help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.icount_child:
        icount_child(args.icount_child, args.family[0], args.n[0], args.t_end, args.rtol, args.atol)
        return
    if args.build_only:
        build_table(args)
        return
    for family in args.family:
        print(f"\n{family}: t_end {args.t_end} s, rtol {args.rtol:g}, atol {args.atol:g}")
        head = (
            "| N | bodies | status | t reached (s) | build (ms) | wall (s) | per eval (us) | per sim. s (ms) "
            "| CPU per sim. s (ms) | nfev | steps | rejected | refused | switches | min sigma | period err (rad) |"
        )
        print(head)
        print("|" + "---|" * (head.count("|") - 1))
        rows = []
        for n in sorted(args.n):
            r = run(family, n, args.t_end, args.rtol, args.atol, args.build_repeats, False)
            r["per_eval"] = r["wall"] / max(r["nfev"], 1) * 1e6
            r["per_s"] = r["wall"] / max(r["t"], 1e-12) * 1e3
            r["cpu_per_s"] = r["cpu"] / max(r["t"], 1e-12) * 1e3
            rows.append(r)
            print(
                f"| {r['N']} | {r['bodies']} | {r['status']} | {r['t']:.3g} | {r['build'] * 1e3:.3g} | {r['wall']:.3g} | {r['per_eval']:.3g} "
                f"| {r['per_s']:.3g} | {r['cpu_per_s']:.3g} | {r['nfev']} | {r['steps']} | {r['rejected']} | {r['refused']} "
                f"| {r['switches']} | {r['min_sigma']:.2g} | {r['err']:.1e} |",
                flush=True,
            )
            if r["wall"] > args.budget:
                print(f"(larger N skipped: {r['wall']:.0f} s > --budget {args.budget:g} s)")
                break
        big = fitted(rows)
        b = [r["bodies"] for r in big]
        print(
            f"exponent (bodies >= 10): per evaluation {slope(b, [r['per_eval'] for r in big]):.2f}, "
            f"per simulated second {slope(b, [r['per_s'] for r in big]):.2f} "
            f"(CPU {slope(b, [r['cpu_per_s'] for r in big]):.2f}), "
            f"build {slope(b, [r['build'] for r in big]):.2f}"
        )
        if args.icount:
            icount_table(family, rows, args, False)


def icount_table(family: str, rows: list[dict[str, Any]], args: argparse.Namespace, build_only: bool) -> None:
    """The instructions of the build and (unless `build_only`) of the run per evaluation and per
    simulated second, for the sizes of `rows`, and their exponents."""
    print(f"\n{family}: instructions (callgrind)")
    print("| N | bodies | build | per eval | per sim. s |\n|---|---|---|---|---|")
    counts = []
    for r in rows:
        c = {**instructions(family, r["N"], args, build_only), "bodies": r["bodies"]}
        counts.append(c)
        per = "| - | - |" if build_only else f"| {c['per_eval']:.4g} | {c['per_s']:.4g} |"
        print(f"| {r['N']} | {r['bodies']} | {c['build']:.4g} {per}", flush=True)
    big = fitted(counts)
    b = [c["bodies"] for c in big]
    runs = (
        ""
        if build_only
        else (
            f"per evaluation {slope(b, [c['per_eval'] for c in big]):.2f}, "
            f"per simulated second {slope(b, [c['per_s'] for c in big]):.2f}, "
        )
    )
    print(f"exponent (bodies >= 10, instructions): {runs}build {slope(b, [c['build'] for c in big]):.2f}")


def build_table(args: argparse.Namespace) -> None:
    """The build's wall time (best of ``--build-repeats``) per family and N, and its exponent."""
    for family in args.family:
        print(f"\n{family}: build only, best of {args.build_repeats}")
        print("| N | bodies | build (ms) |\n|---|---|---|")
        rows = [run(family, n, 0.0, 0.0, 0.0, args.build_repeats, True) for n in sorted(args.n)]
        for r in rows:
            print(f"| {r['N']} | {r['bodies']} | {r['build'] * 1e3:.3g} |", flush=True)
        big = fitted(rows)
        print(f"exponent (bodies >= 10): build {slope([r['bodies'] for r in big], [r['build'] for r in big]):.2f}")
        if args.icount:
            icount_table(family, rows, args, True)


if __name__ == "__main__":
    main()
