"""Small and many runs: the fixed cost of one Python ``Mechanism.simulate`` call over the same
run from Rust, and the serial share of a batch.

- Fixed cost: the four-bar under gravity for 0.01 s (DOP853, rtol = atol = 1e-9, an output
  every 1 ms: 11 rows) from Python minus the same run from Rust (``benchmarks/rust-sim``), in
  CPU time per call (the machine is shared: a call that waits for a core counts in wall time
  only): Python's thread CPU time over a round of calls, Rust's the CPU time of a process
  running them less that of one running a single one (its load and start). ROUNDS rounds
  alternate the two sides; the medians of the rounds are compared.
- Serial share: a batch of VARIANTS four-bar variants (start angles spread around the drawing,
  T_BATCH s each) on two native threads; the main Python thread's CPU time during the call
  over the whole process's. The workers convert and finish their own results holding the
  GIL, so that work (g, measured apart: the same results finished on this thread; their
  conversion to numpy arrays, also under the GIL, is not in it) is serial among them too,
  though it overlaps the other workers' runs. Two idle cores then run the
  batch at least 1 / (s + g + (1 - s - g) / 2) times as fast as one (Amdahl); the wall-time
  speed-up measured here is printed beside it and is only meaningful on an idle machine.

    .venv/bin/python benchmarks/small_runs.py [--calls 10000] [--variants 4000] [--icount]

- With ``--icount``, the fixed cost also in instructions, which the machine's load does not
  change: each side run under valgrind's callgrind for ICOUNT_CALLS[0] and ICOUNT_CALLS[1]
  calls (after a first, untimed one), the difference of the two counts per call (numpy's
  BLAS on one thread: ``ICOUNT_ENV``).

Build ``benchmarks/rust-sim`` first for the Rust side (``benchmarks/run.sh`` does)::

    CARGO_TARGET_DIR=benchmarks/.target cargo build --release --manifest-path benchmarks/rust-sim/Cargo.toml
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import planardyn as pd
from planardyn import batch
from planardyn.batch import simulate as simulate_batch

HERE = Path(__file__).resolve().parent
MODEL = HERE.parent / "examples" / "models" / "four-bar-gravity.yaml"
RUST_SIM = Path(os.environ.get("RUST_SIM", HERE / ".target" / "release" / "planardyn-rust-sim"))
#: The short run: 0.01 s of the four-bar, outputs every 1 ms, at the default tolerances.
T_SHORT, OUTPUT_DT, RTOL = 0.01, 1e-3, 1e-9
#: Each batch variant's run (s).
T_BATCH = 1.0
#: Rounds of the fixed-cost measurement, alternating Python and Rust.
ROUNDS = 5
#: Calls per process of the instruction count (two processes a side, see --icount).
ICOUNT_CALLS = (10, 410)
#: The targets of issue 25, item 4.
FIXED_COST_TARGET_US, SERIAL_SHARE_TARGET = 10.0, 0.05


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def rust_cpu(runs: int) -> float:
    """CPU time (s) of one short run from Rust: a process of runs + 1 less one of 1."""
    cpu = []
    for n in (1, runs + 1):
        c0 = _children_cpu()
        subprocess.run([str(RUST_SIM), str(MODEL), "dop853", repr(RTOL), repr(RTOL), "-", repr(T_SHORT),
                        repr(OUTPUT_DT), str(n)], capture_output=True, check=True)
        cpu.append(_children_cpu() - c0)
    return (cpu[1] - cpu[0]) / runs


def fixed_cost(calls: int) -> dict[str, float]:
    """Medians over the rounds (us) of the short run from Python (wall, thread CPU) and from
    Rust (CPU), and the Python call's fixed cost over the Rust run."""
    mech = pd.load(MODEL)
    kw = dict(method="dop853", rtol=RTOL, atol=RTOL, output_dt=OUTPUT_DT)
    mech.simulate(T_SHORT, **kw)
    per_round = max(1, calls // ROUNDS)
    wall, cpu, rust = [], [], []
    for _ in range(ROUNDS):
        w0, c0 = time.perf_counter(), time.thread_time()
        for _ in range(per_round):
            mech.simulate(T_SHORT, **kw)
        c1, w1 = time.thread_time(), time.perf_counter()
        wall.append((w1 - w0) / per_round)
        cpu.append((c1 - c0) / per_round)
        if RUST_SIM.exists():
            rust.append(rust_cpu(per_round))
    out = {"python_wall_us": statistics.median(wall) * 1e6, "python_cpu_us": statistics.median(cpu) * 1e6}
    if rust:
        out["rust_us"] = statistics.median(rust) * 1e6
        out["fixed_cost_us"] = out["python_cpu_us"] - out["rust_us"]
    return out


#: The Python side's BLAS with one thread under callgrind: numpy's OpenBLAS worker threads spin
#: while idle, and valgrind, running one thread at a time, counted 15-19k instructions a call of
#: theirs that no call makes (no BLAS routine is on its path; the CPU time above is the calling
#: thread's alone).
ICOUNT_ENV = {"OPENBLAS_NUM_THREADS": "1"}


def _instructions(command: list[str]) -> int:
    """Instructions callgrind counts in a run of ``command`` (its ``Collected`` line)."""
    out = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", *command],
                         capture_output=True, text=True, check=True, env={**os.environ, **ICOUNT_ENV}).stderr
    return int(re.search(r"Collected : (\d+)", out).group(1))  # type: ignore[union-attr]


def instructions_per_call() -> dict[str, float]:
    """Instructions of one short run from Python and from Rust, and the difference: the
    counts of processes making ICOUNT_CALLS[1] and ICOUNT_CALLS[0] calls, less each other."""
    python = [sys.executable, __file__, "--calls-only"]
    rust = [str(RUST_SIM), str(MODEL), "dop853", repr(RTOL), repr(RTOL), "-", repr(T_SHORT), repr(OUTPUT_DT)]
    n0, n1 = ICOUNT_CALLS
    per_call = {side: (_instructions(cmd + [str(n1 + 1)]) - _instructions(cmd + [str(n0 + 1)])) / (n1 - n0)
                for side, cmd in (("python", python), ("rust", rust))}
    return {**per_call, "fixed": per_call["python"] - per_call["rust"]}


def calls_only(n: int) -> None:
    """n short runs from Python and nothing else (the process callgrind counts)."""
    mech = pd.load(MODEL)
    for _ in range(n):
        mech.simulate(T_SHORT, method="dop853", rtol=RTOL, atol=RTOL, output_dt=OUTPUT_DT)


def serial_share(variants: int, threads: int = 2) -> dict[str, float]:
    """Main-thread CPU time over process CPU time of one batch call, and its wall time."""
    mech = pd.load(MODEL)
    q0 = np.asarray(mech.q0)
    items = [(mech, {"q0": q0 + 1e-4 * k}) for k in range(variants)]
    simulate_batch(items[:threads], T_BATCH, threads=threads)
    w0, c0, p0 = time.perf_counter(), time.thread_time(), time.process_time()
    out = simulate_batch(items, T_BATCH, threads=threads)
    w1, c1, p1 = time.perf_counter(), time.thread_time(), time.process_time()
    assert all(r.success for r in out), [str(r) for r in out if not r.success][:3]
    # The finish the workers do under the GIL, timed here on the raw results of the same runs.
    _, _, prepared = batch._prepare(items, lambda m, own: batch._settings({"t_end": T_BATCH}, own, m))
    raws = batch._run_chunk("simulate", prepared, threads)
    f0 = time.thread_time()
    for raw, (m, settings) in zip(raws, prepared):
        m._result(raw, settings)
    held = time.thread_time() - f0
    return {"main_cpu_s": c1 - c0, "process_cpu_s": p1 - p0, "wall_s": w1 - w0, "share": (c1 - c0) / (p1 - p0),
            "gil_share": held / (p1 - p0)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=10_000)
    ap.add_argument("--variants", type=int, default=4000)
    ap.add_argument("--icount", action="store_true", help="also count the instructions of a call (valgrind)")
    ap.add_argument("--calls-only", type=int, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.calls_only is not None:
        calls_only(a.calls_only)
        return
    if a.icount:
        i = instructions_per_call()
        print(f"instructions a call (callgrind, {ICOUNT_CALLS[1]} less {ICOUNT_CALLS[0]} calls): Python "
              f"{i['python']:.0f}, Rust {i['rust']:.0f}; fixed cost {i['fixed']:.0f}")
    f = fixed_cost(a.calls)
    print(f"one call, four-bar {T_SHORT} s ({a.calls} calls in {ROUNDS} rounds, medians): Python "
          f"{f['python_wall_us']:.1f} us wall, {f['python_cpu_us']:.1f} us thread CPU", end="")
    if "rust_us" in f:
        print(f"; Rust {f['rust_us']:.1f} us CPU; fixed cost {f['fixed_cost_us']:.1f} us "
              f"(target <= {FIXED_COST_TARGET_US:g} us)")
    else:
        print(f"; {RUST_SIM} is not built: no Rust side")
    one = serial_share(a.variants, threads=1)
    two = serial_share(a.variants, threads=2)
    s, g = two["share"], two["gil_share"]
    print(f"batch of {a.variants} four-bar runs of {T_BATCH} s on 2 threads: main thread {two['main_cpu_s']:.3f} s "
          f"of {two['process_cpu_s']:.3f} s CPU, serial share {s:.1%} (target <= {SERIAL_SHARE_TARGET:.0%}); "
          f"finishing under the GIL in the workers {g:.1%}; "
          f"speed-up on two idle cores >= {1 / (s + g + (1 - s - g) / 2):.2f}x by Amdahl, "
          f"{one['wall_s'] / two['wall_s']:.2f}x measured in wall time ({one['wall_s']:.2f} s on 1, "
          f"{two['wall_s']:.2f} s on 2; load average {os.getloadavg()[0]:.1f})")


if __name__ == "__main__":
    main()
