"""The cheapest setting of a tool that meets a target, found exactly rather than picked from a sweep.

A setting is an integer along which the cost grows: the number of fixed steps n over the run
(dt = t_end / n), or for an adaptive integrator a tolerance index k, rtol = atol = 10^(-k / PER_DECADE).
The accuracy at a fixed setting is deterministic (the same run gives the same drift, gap and error
to the bit), so a pass/fail test of a setting is exact, and bisection between a failing and a
passing setting finds an adjacent pair: the setting s* that passes and s* - 1 that fails.

Accuracy need not be monotone in the setting (a drift that happens to cancel at one step size, a
tolerance at which the step sequence happens to land well), so ``cheapest`` does not trust a single
pass:

1. *scan*: walk the grid upward (cheap to expensive; consecutive points no more than SCAN_RATIO
   apart) until CONFIRM consecutive grid points pass: the onset of passing for good. Passes before
   that onset, followed by a failure, are *isolated* and are reported, not used;
2. *bisect*: between the last failing grid point below the onset and the onset itself, down to
   adjacent integers: s* passes, s* - 1 fails;
3. *check the neighbours*: s* + 1 ... s* + NEIGHBOURS must pass too; if one fails, the search
   starts again from step 1 above it (an onset of CONFIRM grid points above the failing neighbour,
   bisection between them).

The result passes at s* and at its NEIGHBOURS next dearer settings, fails at s* - 1 (the safety
margin is one setting: 1/n of the steps, or 1/PER_DECADE of a decade of tolerance), and CONFIRM
consecutive grid points from the first at or above s* pass (a span of SCAN_RATIO^(CONFIRM - 1)).
What it cannot see is a failing integer between grid points above s* + NEIGHBOURS that the scan
skipped.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

#: The coarsest ratio between neighbouring scan points (issue 23: a grid no coarser than 1.1x a step).
SCAN_RATIO = 1.1
#: Consecutive passing scan points that make the onset of passing (a span of 1.1^2 = 1.21x).
CONFIRM = 3
#: The next dearer settings that must pass as well as the one found (fewer than CONFIRM, so that
#: they lie within the confirmed span).
NEIGHBOURS = 2
#: Tolerance indices per decade: k -> rtol = 10^(-k / PER_DECADE); one index is a factor 1.023.
PER_DECADE = 100
#: Tolerance scan step in indices: 10^(4 / 100) = 1.096, within SCAN_RATIO.
TOL_SCAN_STEP = 4


@dataclass
class Found:
    """What ``cheapest`` found, and the evidence."""

    setting: int | None  # the cheapest passing setting, None if no grid point passes
    below: int | None  # the failing setting just below it (setting - 1); None if the cheapest tried passes
    tried: dict[int, bool] = field(default_factory=dict)  # every setting evaluated -> passed, in order
    isolated: list[int] = field(default_factory=list)  # passing settings below the onset, ignored
    note: str = ""

    @property
    def bracketed(self) -> bool:
        return self.setting is not None and self.below is not None


def steps_grid(lo: int, hi: int, ratio: float = SCAN_RATIO) -> list[int]:
    """Integers from lo to hi (both included), each at most ``ratio`` times the one before."""
    if not (1 <= lo < hi) or ratio <= 1.0:
        raise ValueError(f"steps_grid needs 1 <= lo < hi and ratio > 1, got lo={lo}, hi={hi}, ratio={ratio}")
    grid = [lo]
    while grid[-1] < hi:
        grid.append(min(hi, max(grid[-1] + 1, math.floor(grid[-1] * ratio))))
    return grid


def tolerance_grid(loosest: float, tightest: float) -> list[int]:
    """Tolerance indices from the loosest to the tightest rtol, TOL_SCAN_STEP apart."""
    lo, hi = (round(-PER_DECADE * math.log10(x)) for x in (loosest, tightest))
    return list(range(lo, hi + 1, TOL_SCAN_STEP))


def rtol(k: int) -> float:
    """The tolerance of index k."""
    return 10.0 ** (-k / PER_DECADE)


def cheapest(passes: Callable[[int], bool], grid: Sequence[int], *, confirm: int = CONFIRM,
             neighbours: int = NEIGHBOURS) -> Found:
    """The cheapest setting that passes, by scan, bisection and a check of its neighbours (module
    docstring). ``grid``: ascending settings, cheapest first. ``passes`` is called at most once per
    setting."""
    if not 0 <= neighbours < confirm:
        raise ValueError(f"need 0 <= neighbours < confirm, got neighbours={neighbours}, confirm={confirm}")
    found = Found(None, None)

    def ok(s: int) -> bool:
        if s not in found.tried:
            found.tried[s] = bool(passes(s))
        return found.tried[s]

    def note(text: str) -> None:
        found.note = f"{found.note}; {text}" if found.note else text

    lo = None  # the dearest setting known to fail below the answer
    while True:
        first = 0 if lo is None else next((i for i, s in enumerate(grid) if s > lo), len(grid))
        onset, run = None, 0
        for i in range(first, len(grid)):
            if ok(grid[i]):
                onset, run = (i if run == 0 else onset), run + 1
                if run == confirm:
                    break
            else:
                run = 0
        if onset is None or run == 0:
            note(f"no setting passes for good up to {grid[-1]}")
            return found
        if run < confirm:
            note(f"passing confirmed by only {run} grid point(s) at the dear end of the range")
        if onset == 0:
            found.setting = grid[0]
            note("the cheapest setting tried passes (not bracketed)")
            return found
        low, hi = max(grid[onset - 1], lo if lo is not None else grid[onset - 1]), grid[onset]
        while hi - low > 1:  # low fails, hi passes
            mid = (low + hi) // 2
            low, hi = (low, mid) if ok(mid) else (mid, hi)
        lo = next((s for s in range(hi + 1, hi + 1 + neighbours) if not ok(s)), None)
        if lo is None:
            found.setting, found.below = hi, low
            found.isolated = sorted(s for s, v in found.tried.items() if v and s < hi)
            return found
