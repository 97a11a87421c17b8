"""The search for a tool's cheapest passing setting (cheapest.py) on synthetic pass/fail functions
whose answers are known exactly. Run with ``.venv/bin/python -m pytest -q benchmarks``."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import cheapest as C  # noqa: E402

GRID = C.steps_grid(50, 40000)


def counted(f):
    calls = []

    def g(s):
        calls.append(s)
        return f(s)

    return g, calls


def test_grid_is_no_coarser_than_the_ratio():
    assert GRID[0] == 50 and GRID[-1] == 40000
    ratios = [b / a for a, b in zip(GRID, GRID[1:])]
    assert max(ratios) <= C.SCAN_RATIO and min(ratios) > 1.0
    # From 1: steps of one until floor(1.1 n) exceeds n + 1, which it first does at n = 20 (22).
    assert C.steps_grid(1, 25) == [*range(1, 21), 22, 24, 25]
    k = C.tolerance_grid(1e-2, 1e-12)
    assert (k[0], k[-1], len(k)) == (200, 1200, 251)
    assert 10 ** (C.TOL_SCAN_STEP / C.PER_DECADE) <= C.SCAN_RATIO
    assert C.rtol(600) == pytest.approx(1e-6, rel=1e-15)


def test_monotone_threshold_is_found_exactly():
    # Passing from 1234 steps on: the answer is 1234, and 1233 was seen to fail.
    f, calls = counted(lambda n: n >= 1234)
    found = C.cheapest(f, GRID)
    assert (found.setting, found.below, found.isolated) == (1234, 1233, [])
    assert found.bracketed and found.tried[1233] is False and found.tried[1235] is True
    assert len(calls) == len(set(calls))  # each setting evaluated once
    # The scan stops CONFIRM grid points past the threshold; bisection of the 1.1x interval
    # below it takes at most log2(0.1 * 1234) + 1 = 8 evaluations, the neighbours 2.
    scanned = [s for s in GRID if s <= 1234 * C.SCAN_RATIO ** C.CONFIRM]
    assert len(calls) <= len(scanned) + 8 + C.NEIGHBOURS


def test_isolated_pass_and_hole_above_the_threshold():
    # Non-monotone: one grid point well below the threshold passes by luck (a cancelling drift),
    # and 1001, just above the threshold 1000, fails. The lucky point is reported, not used;
    # bisection lands on 1000, its neighbour 1001 fails, bisection again above it gives 1002,
    # whose neighbours 1003 and 1004 pass.
    lucky = GRID[GRID.index(next(s for s in GRID if s > 700))]
    f, _ = counted(lambda n: n == lucky or (n >= 1000 and n != 1001))
    found = C.cheapest(f, GRID)
    assert (found.setting, found.below) == (1002, 1001)
    assert found.isolated == [lucky, 1000]
    assert found.tried[1003] and found.tried[1004]


def test_short_passing_run_is_not_the_onset():
    # Two consecutive grid points pass (fewer than CONFIRM = 3), then one fails: the onset is
    # the next run of three. With passes on [g5, g6] and from g9 on, the answer lies in (g8, g9].
    g = GRID
    f, _ = counted(lambda n: n in (g[5], g[6]) or n >= g[8] + 1)
    found = C.cheapest(f, g)
    assert (found.setting, found.below) == (g[8] + 1, g[8])
    assert found.isolated == [g[5], g[6]]


def test_holes_beyond_the_confirmed_span_restart_the_scan():
    # On the tolerance grid (every 4th index): from 600 on, every index = 1 or 2 (mod 4) fails up
    # to 640. Each bisection lands on 4j + 3 (4j + 2 fails) and its neighbour 4j + 5 fails, so
    # the search climbs past the three confirmed grid points and must scan again above each
    # failing neighbour; the first setting with two passing neighbours is 639 (640, 641 pass).
    grid = C.tolerance_grid(1e-2, 1e-12)
    found = C.cheapest(lambda k: k >= 600 and (k >= 640 or k % 4 in (0, 3)), grid)
    assert (found.setting, found.below) == (639, 638)
    assert found.tried[640] and found.tried[641] and found.note == ""


def test_none_and_not_bracketed():
    found = C.cheapest(lambda n: False, GRID)
    assert found.setting is None and "no setting passes for good up to 40000" in found.note
    found = C.cheapest(lambda n: True, GRID)
    assert (found.setting, found.below, found.bracketed) == (50, None, False)
    assert "not bracketed" in found.note
    # Passing only at the dear end, fewer than CONFIRM points: accepted, with the caveat.
    found = C.cheapest(lambda n: n >= 39000, GRID)
    assert (found.setting, found.below) == (39000, 38999) and "only 2 grid point(s)" in found.note


def test_tolerance_index_in_log_space():
    # Passing for rtol <= 3e-7 (index k >= 100 * 6.52 = 652.3, so from k = 653), looser fails.
    grid = C.tolerance_grid(1e-2, 1e-12)
    found = C.cheapest(lambda k: C.rtol(k) <= 3e-7, grid)
    assert (found.setting, found.below) == (653, 652)
    assert C.rtol(653) <= 3e-7 < C.rtol(652)
    assert math.log10(C.rtol(652) / C.rtol(653)) == pytest.approx(1 / C.PER_DECADE, rel=1e-12)


def test_bad_arguments_are_refused():
    with pytest.raises(ValueError, match="lo < hi"):
        C.steps_grid(10, 10)
    with pytest.raises(ValueError, match="neighbours"):
        C.cheapest(lambda n: True, GRID, confirm=2, neighbours=2)
