"""Guards of a long simulation: Ctrl-C stops it with its trajectory kept, and its output
rows must fit in memory.

A run's trajectory lives in memory until it is written. :func:`rows_message` refuses up
front a run whose output rows cannot fit; :class:`RunGuard`, passed as the ``progress``
callback of ``Mechanism.simulate``, stops a run (status ``'cancelled'``, trajectory so far
kept) on Ctrl-C, or when the process has grown by half the memory that was available at
the start (a run that outputs every step has no row count known up front).
"""

from __future__ import annotations

import os
import signal
import threading
from collections.abc import Callable
from types import FrameType
from typing import Any

#: Peak memory of a run per byte of output rows: the core's growing arrays (up to twice
#: their length), the arrays handed to Python, and the table a results file is written from.
PEAK_FACTOR = 4
#: Share of the memory available at the start a run may grow by before it is stopped.
GROWTH_SHARE = 0.5
#: Output rows that need at most this many bytes at their peak are never refused, and the
#: memory is not read for them: reading /proc/meminfo (about 10 us) cost more than a short
#: run's whole fixed cost in Python, and a process that cannot get 1 MiB more fails at its
#: next allocation whatever the guard says.
ALWAYS_FITS = 2**20


def available_memory() -> int | None:
    """Bytes of memory the system can give without swapping (Linux MemAvailable, else free
    pages), or None where it cannot tell."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, AttributeError):
        return None


def resident_memory() -> int | None:
    """Bytes of memory this process holds now (Linux), or None where it cannot tell."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError, AttributeError):
        return None


def row_bytes(m: int, n_bodies: int) -> int:
    """Bytes of one output row: t, q, qd, qdd, tau (m each), three energies, sigma,
    residual, x and xd (3 per body) as float64, and the partitioned flag."""
    return 8 * (1 + 4 * m + 3 + 2 + 6 * n_bodies) + 1


def needed_bytes(rows: float, m: int, n_bodies: int) -> float:
    """Peak bytes of a run with ``rows`` output rows."""
    return rows * row_bytes(m, n_bodies) * PEAK_FACTOR


def rows_message(rows: float, m: int, n_bodies: int, available: int | None) -> str | None:
    """Why ``rows`` output rows cannot be held in ``available`` bytes, or None if they can
    (or nothing is known of the memory)."""
    need = needed_bytes(rows, m, n_bodies)
    if available is None or need <= available:
        return None
    return (f"{rows:.4g} output rows need about {need / 2**30:.3g} GiB, more than the "
            f"{available / 2**30:.3g} GiB of memory available")


class RunGuard:
    """A progress callback that stops a run on Ctrl-C or when its memory runs out, keeping
    the trajectory computed so far.

    Used as a context manager around ``Mechanism.simulate(progress=guard)``: inside, the
    first Ctrl-C asks the run to stop at its next progress call (about every 1% of the
    run), a second one interrupts at once (KeyboardInterrupt, the trajectory lost).
    ``reason`` says why the run was stopped, None if it was not.
    """

    def __init__(self, progress: Callable[[float], Any] | None = None, memory: bool = True) -> None:
        self.progress = progress
        self.reason: str | None = None
        self.interrupted = False
        start, available = resident_memory(), available_memory()
        self.limit = None if not memory or start is None or available is None else start + GROWTH_SHARE * available
        self._previous: Any = None

    def _on_sigint(self, signum: int, frame: FrameType | None) -> None:
        if self.interrupted:
            raise KeyboardInterrupt
        self.interrupted = True

    def __enter__(self) -> RunGuard:
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self._on_sigint)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
            self._previous = None

    def __call__(self, t: float) -> bool:
        if self.progress is not None:
            self.progress(t)
        if self.interrupted:
            self.reason = f"interrupted (Ctrl-C) at t = {t:.6g} s: the trajectory so far is kept"
            return False
        used = resident_memory() if self.limit is not None else None
        if used is not None and self.limit is not None and used > self.limit:
            self.reason = (f"stopped at t = {t:.6g} s: the trajectory would not fit in memory "
                           f"({used / 2**30:.3g} GiB in use)")
            return False
        return True
