"""The size families of benchmarks/scaling.py: their closed forms, and a type II measure and an
integrator that do not depend on their size (docs/formulation.md, *Per group*).

    .venv/bin/python -m pytest -q benchmarks/test_families.py
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

from families import a02, five_bars, parallelograms, pendulum_period  # noqa: E402

pd = pytest.importorskip("planardyn")

THETA0 = math.radians(30)


def test_pendulum_period_matches_the_power_series_of_k():
    # T = 4 K(m) / sqrt(g) with m = sin^2(theta0 / 2), K(m) = pi / 2 sum ((2n)! / (2^2n n!^2))^2 m^n
    # (Abramowitz & Stegun 17.3.11), summed independently of the AGM in families.py.
    m = math.sin(THETA0 / 2) ** 2
    k = math.pi / 2 * sum((math.comb(2 * n, n) / 4**n) ** 2 * m**n for n in range(40))
    assert pendulum_period(THETA0) == pytest.approx(4 * k / math.sqrt(9.81), rel=1e-14)
    assert pendulum_period(1e-9) == pytest.approx(2 * math.pi / math.sqrt(9.81), rel=1e-15)


@pytest.mark.parametrize("n", [1, 7])
def test_parallelogram_chain_swings_with_the_simple_pendulum_period(n):
    # Every N is a simple pendulum of 1 m: back at theta0 after one closed-form period. The
    # integrator's own error at rtol 1e-10 is ~1e-11 rad (scaling.py reports 4e-11 at rtol 1e-9).
    mech = pd.from_dict(parallelograms(n, THETA0))
    period = pendulum_period(THETA0)
    res = mech.simulate(t_end=period, rtol=1e-10, atol=1e-12, t_eval=[0.0, period])
    assert res.success
    assert res.q[-1, 0] == pytest.approx(-math.pi / 2 + THETA0, abs=1e-9)


@pytest.mark.parametrize("spec", [a02(80), parallelograms(80, THETA0)], ids=["a02", "parallelograms"])
def test_every_window_is_an_exact_parallelogram(spec):
    # Tips drawn exactly one apart, as the ground points are: a window whose coupler is off by
    # an ulp has imperfect change points (with cos(pi/2) = 6.1e-17 unrounded, A02's first
    # coupler was 1.1e-16 m short of its ground).
    points = spec["points"]
    for i in range(1, 81):
        assert [b - a for a, b in zip(points[f"A{i - 1}"], points[f"A{i}"])] == [1.0, 0.0]
        assert [b - a for a, b in zip(points[f"O{i}"], points[f"A{i}"])] == points["A0"]
    assert math.hypot(*points["A0"]) == pytest.approx(1.0, abs=1e-12)


def test_type_ii_measure_is_the_same_for_every_length_of_chain():
    # Every group of the chain is the same dyad at the same length, so the measure is too; the
    # smallest singular value of the whole J fell from 0.19 (N = 1) to 5.8e-4 (N = 40) here.
    sigmas = [
        pd.from_dict(parallelograms(n, THETA0)).kinematics([-math.pi / 2 + THETA0])["sigma_min"] for n in (1, 5, 40)
    ]
    assert sigmas[0] > 0.3
    np.testing.assert_allclose(sigmas, sigmas[0], rtol=1e-12)


def test_five_bars_side_by_side_measure_as_one():
    one = pd.from_dict(five_bars(1)).kinematics([-2 * math.pi / 3, -math.pi / 3])["sigma_min"]
    many = pd.from_dict(five_bars(6)).kinematics([-2 * math.pi / 3, -math.pi / 3] * 6)["sigma_min"]
    assert many == pytest.approx(one, rel=1e-12)


@pytest.mark.parametrize("n", [2, 20])
def test_a02_before_its_first_change_point_needs_no_refusal_at_any_size(n):
    # Before: 0, 1, 13, 93 refused evaluations at N = 2, 5, 10, 20 in this half second, and
    # chart switches from N = 5 on (docs/benchmarks.md, Cost against size).
    res = pd.from_dict(a02(n)).simulate(t_end=0.5, rtol=1e-9, atol=1e-12)
    assert res.success
    assert res.stats["failed_evaluations"] == 0 and res.stats["chart_switches"] == 0
