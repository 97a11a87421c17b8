"""The candidates' times, measured side by side in one run.

Every candidate (a tool's cheapest passing setting of one method for one target, found by
cheapest.py) is called once per round, in one order on even rounds and the reverse on odd ones
(A B C, C B A, A B C, ...), so that a change in the machine's speed (other work, the CPU's clock)
falls on all of them alike, and no candidate always follows the same one. A sample is the mean
over a batch of back-to-back calls at least MIN_SAMPLE long, so that the clock's resolution and
a call's fixed costs do not decide a short run's time. Per candidate: the median over the rounds
and the quartiles; between two candidates, the ratio is taken within each round (the same
moment) and its median and quartiles quoted.

Besides the wall time, each sample records the CPU time of the calling thread
(``time.thread_time``) and of the whole process (``time.process_time``, which also counts a
tool's own worker threads): on a machine shared with other work the CPU times vary much less
than the wall time, and a tool whose process time exceeds its thread time ran threads of its own.
"""

from __future__ import annotations

import math
import os
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass, field

#: The shortest sample (s): shorter calls are repeated back to back and averaged.
MIN_SAMPLE = 0.01
#: Rounds of the full set of candidates (each candidate's median is over these).
ROUNDS = 15


@dataclass
class Entry:
    """One call to time, and its samples (s per call, one per round)."""

    key: str
    fn: Callable[[], object]
    batch: int = 1
    wall: list[float] = field(default_factory=list)
    thread: list[float] = field(default_factory=list)
    process: list[float] = field(default_factory=list)
    #: What fn returned, per call, where it returns a number (Pinocchio's clocked C++ seconds).
    value: list[float] = field(default_factory=list)

    def sample(self) -> None:
        out = 0.0
        w0, t0, p0 = time.perf_counter(), time.thread_time(), time.process_time()
        for _ in range(self.batch):
            r = self.fn()
            out += r if isinstance(r, float) else 0.0
        w1, t1, p1 = time.perf_counter(), time.thread_time(), time.process_time()
        self.wall.append((w1 - w0) / self.batch)
        self.thread.append((t1 - t0) / self.batch)
        self.process.append((p1 - p0) / self.batch)
        self.value.append(out / self.batch)


def quartiles(xs: list[float]) -> dict:
    """Median, quartiles (inclusive method: within the samples' range) and the extremes."""
    if len(xs) < 2:
        v = xs[0] if xs else math.nan
        return {"median": v, "q1": v, "q3": v, "min": v, "max": v}
    q1, med, q3 = statistics.quantiles(xs, n=4, method="inclusive")
    return {"median": med, "q1": q1, "q3": q3, "min": min(xs), "max": max(xs)}


def paired(a: list[float], b: list[float]) -> dict:
    """Quartiles of the per-round ratio a_i / b_i."""
    return quartiles([x / y for x, y in zip(a, b)])


def measure(calls: dict[str, Callable[[], object]], rounds: int = ROUNDS,
            say: Callable[[str], None] = print) -> dict:
    """Time every call, interleaved over the rounds. Returns, JSON-ready: per key its batch, the
    per-round samples and their quartiles; the load average at the start and the end, and the
    1-minute load after every round."""
    entries = [Entry(k, fn) for k, fn in calls.items()]
    for e in entries:  # warm-up call, which also sizes the batch
        t0 = time.perf_counter()
        e.fn()
        e.batch = max(1, math.ceil(MIN_SAMPLE / max(time.perf_counter() - t0, 1e-9)))
    load_start, loads, t0 = os.getloadavg(), [], time.perf_counter()
    for r in range(rounds):
        for e in entries if r % 2 == 0 else entries[::-1]:
            e.sample()
        loads.append(os.getloadavg()[0])
    say(f"  timed {len(entries)} calls x {rounds} rounds in {time.perf_counter() - t0:.1f} s, "
        f"load average {'/'.join(f'{x:.2f}' for x in load_start)} -> "
        f"{'/'.join(f'{x:.2f}' for x in os.getloadavg())}")
    return {"rounds": rounds, "min_sample_s": MIN_SAMPLE, "load_average_at_start": load_start,
            "load_average_at_end": os.getloadavg(), "load_1min_per_round": loads,
            "entries": {e.key: {"batch": e.batch, "wall": e.wall, "thread_cpu": e.thread, "process_cpu": e.process,
                                "value": e.value, "wall_stats": quartiles(e.wall),
                                "thread_cpu_stats": quartiles(e.thread), "process_cpu_stats": quartiles(e.process)}
                        for e in entries}}
