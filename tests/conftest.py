"""Shared fixtures: small models written here (so the API tests do not depend on the shipped
model files, which have their own tests), and the paths of the shipped ones.

Every number of these models is chosen here; the expected values the tests compare against
are derived from them in closed form (see each test's comment).
"""

from __future__ import annotations

import contextlib
import io
import math
import os
from pathlib import Path

import pytest
from hypothesis import settings

# CI runs the property tests on fixed examples (a red CI must be reproducible); locally
# hypothesis keeps exploring new ones.
settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "examples" / "models"

# ---------------------------------------------------------------- a simple pendulum
# One body hanging from a revolute pair at O; q = angle from the downward vertical (rad,
# counter-clockwise), so the centre of mass is at l (sin q, -cos q).
PENDULUM_M = 2.0  # kg
PENDULUM_I = 0.05  # kg m^2 about the centre of mass
PENDULUM_L = 0.6  # m, pivot to centre of mass
G = 9.81  # m/s^2


def pendulum_dict() -> dict:
    return {
        "name": "pendulum",
        "units": "SI",
        "gravity": [0.0, -G],
        "points": {"O": [0.0, 0.0], "A": [0.0, -1.0]},
        "ground": ["O"],
        "bodies": {
            "bob": {
                "points": ["O", "A"],
                "mass": PENDULUM_M,
                "inertia": PENDULUM_I,
                "com": [0.0, -PENDULUM_L],
            }
        },
        "pairs": [{"type": "revolute", "name": "pivot", "at": "O", "bodies": ["ground", "bob"]}],
        "coordinates": [{"name": "theta", "pair": "pivot", "value": 0.0}],
    }


# ---------------------------------------------------------------- a crank-rocker four-bar
# Grashof crank-rocker: crank a (shortest) + coupler b (longest) = 1.3 <= rocker c + ground d
# = 1.7, so the crank turns fully and the transmission angle never reaches 0 or 180 deg:
# the position is regular (no singularity) at every crank angle.
FOUR_BAR_A, FOUR_BAR_B, FOUR_BAR_C, FOUR_BAR_D = 0.3, 1.0, 0.8, 0.9  # m
FOUR_BAR_THETA0 = math.pi / 3  # rad, drawn crank angle


def four_bar_B(theta: float, a=FOUR_BAR_A, b=FOUR_BAR_B, c=FOUR_BAR_C, d=FOUR_BAR_D) -> tuple[float, float]:
    """Closed form of the coupler-rocker joint B for crank angle theta (Freudenstein's
    geometry: B is where the circles |B - A| = b and |B - D| = c meet), on the upper branch
    (B to the left of A->D, as drawn)."""
    ax, ay = a * math.cos(theta), a * math.sin(theta)
    dx, dy = d - ax, -ay
    e = math.hypot(dx, dy)
    along = (b * b - c * c + e * e) / (2 * e)
    h = math.sqrt(b * b - along * along)
    ux, uy = dx / e, dy / e
    return ax + along * ux - h * uy, ay + along * uy + h * ux


def four_bar_dict() -> dict:
    theta = FOUR_BAR_THETA0
    A = [FOUR_BAR_A * math.cos(theta), FOUR_BAR_A * math.sin(theta)]
    B = list(four_bar_B(theta))
    return {
        "name": "crank-rocker four-bar",
        "units": "SI",
        "gravity": [0.0, -G],
        "points": {"O": [0.0, 0.0], "A": A, "B": B, "D": [FOUR_BAR_D, 0.0]},
        "ground": ["O", "D"],
        "bodies": {
            "crank": {"points": ["O", "A"], "uniform_bar": ["O", "A"], "mass": 0.3},
            "coupler": {"points": ["A", "B"], "uniform_bar": ["A", "B"], "mass": 1.0},
            "rocker": {"points": ["D", "B"], "uniform_bar": ["D", "B"], "mass": 0.8},
        },
        "pairs": [
            {"type": "revolute", "name": "crank_pivot", "at": "O", "bodies": ["ground", "crank"]},
            {"type": "revolute", "name": "elbow", "at": "A", "bodies": ["crank", "coupler"]},
            {"type": "revolute", "name": "wrist", "at": "B", "bodies": ["coupler", "rocker"]},
            {"type": "revolute", "name": "rocker_pivot", "at": "D", "bodies": ["ground", "rocker"]},
        ],
        "coordinates": [{"name": "theta", "pair": "crank_pivot", "value": theta}],
        "drives": [{"coordinate": "theta", "effort": 1.5}],
        "simulate": {"t_end": 1.0, "output_dt": 0.01},
    }


@pytest.fixture
def pendulum():
    import planardyn

    return planardyn.from_dict(pendulum_dict())


@pytest.fixture
def four_bar():
    import planardyn

    return planardyn.from_dict(four_bar_dict())


@pytest.fixture(autouse=True, scope="session")
def _headless_matplotlib():
    os.environ.setdefault("MPLBACKEND", "Agg")
    yield


def shipped_models() -> list[Path]:
    return sorted(MODELS.glob("*.yaml")) + sorted(MODELS.glob("*.json"))


def cli_run(*argv: object) -> tuple[int, str]:
    """Exit status and stderr of ``planardyn ARGV`` run in this process (stdout dropped); an
    exception escaping ``cli.main`` fails the test with its traceback."""
    from planardyn.cli import main

    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main([str(a) for a in argv])
        except SystemExit as e:  # argparse's usage errors
            code = e.code if isinstance(e.code, int) else 2
    return code, err.getvalue()
