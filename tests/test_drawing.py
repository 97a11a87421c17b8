"""Help for drawing a mechanism: an angle that looks like degrees is warned about, the
point-from-lengths helper gives the shipped four-bar's drawing, a pin joining three bodies
takes two pairs (three repeat two constraints, which the loader reports).

Expected values: four-bar-gravity.yaml's point B (its file, reproduced from
tests/data/benchmarks); 30 deg = pi/6 = 0.523599 rad.
"""

from __future__ import annotations

import math
import warnings

import planardyn as pd
import pytest
import yaml
from planardyn import models
from planardyn.library import circle_intersection


def four_bar(**coordinate) -> str:
    d = yaml.safe_load(models.path("four-bar-gravity").read_text())
    d["coordinates"][0].update(coordinate)
    return yaml.safe_dump(d)


def loaded_warnings(text: str) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pd.loads(text, source="four-bar.yaml")
    return [str(w.message) for w in caught if issubclass(w.category, pd.PlanardynWarning)]


def test_an_angle_of_30_rad_is_warned_about_as_likely_degrees():
    (message,) = loaded_warnings(four_bar(value=30.0, q0=30.0))
    assert message.startswith("four-bar.yaml: coordinates[0].value of angle 'theta1' is 30 rad, more than a full turn")
    assert message.endswith("if 30 is in degrees, write 0.523599")


def test_q0_beyond_a_turn_is_named_as_q0():
    (message,) = loaded_warnings(four_bar(value=6.0, q0=6.5))
    assert "coordinates[0].q0 of angle 'theta1' is 6.5 rad" in message


@pytest.mark.parametrize("value", [1.0471975511965976, -6.28, 6.28])
def test_angles_within_a_turn_load_silently(value):
    assert loaded_warnings(four_bar(value=value, q0=value)) == []


def test_circle_intersection_gives_the_four_bars_drawing():
    d = yaml.safe_load(models.path("four-bar-gravity").read_text())["points"]
    A = (0.5 * math.cos(math.radians(60)), 0.5 * math.sin(math.radians(60)))  # the 0.5 m crank at 60 deg
    B = circle_intersection(A, 1.2, d["D"], 1.0, mode=+1)  # coupler 1.2 m, rocker 1.0 m
    assert B == pytest.approx(d["B"], abs=1e-12)
    assert circle_intersection(A, 1.2, d["D"], 1.0, mode=-1)[1] < 0  # the other assembly, below A -> D


PIN_OF_THREE = """
name: six-bar with a pin of three bodies at B
points: {O: [0, 0], D: [1, 0], F: [2, 0], A: [0.25, 0.433], B: [1.2, 0.9], E: [1.8, 1.0]}
ground: [O, D, F]
bodies:
  crank: {points: [O, A], uniform_bar: [O, A], mass: 1}
  coupler: {points: [A, B], uniform_bar: [A, B], mass: 1}
  rocker: {points: [D, B], uniform_bar: [D, B], mass: 1}
  link1: {points: [B, E], uniform_bar: [B, E], mass: 1}
  link2: {points: [F, E], uniform_bar: [F, E], mass: 1}
pairs:
  - {type: revolute, name: O, at: O, bodies: [ground, crank]}
  - {type: revolute, name: A, at: A, bodies: [crank, coupler]}
  - {type: revolute, name: B1, at: B, bodies: [coupler, rocker]}
  - {type: revolute, name: B2, at: B, bodies: [coupler, link1]}
  - {type: revolute, name: D, at: D, bodies: [ground, rocker]}
  - {type: revolute, name: E, at: E, bodies: [link1, link2]}
  - {type: revolute, name: F, at: F, bodies: [ground, link2]}
coordinates:
  - {name: theta, pair: O, value: 1.0472}
"""


def test_a_pin_of_k_bodies_takes_k_minus_1_pairs():
    assert loaded_warnings(PIN_OF_THREE) == []  # 3*5 - 2*7 = 1
    ring = PIN_OF_THREE.replace("  - {type: revolute, name: D,",
                                "  - {type: revolute, name: B3, at: B, bodies: [rocker, link1]}\n"
                                "  - {type: revolute, name: D,")
    messages = loaded_warnings(ring)  # 3*5 - 2*8 = -1, yet it moves with 1
    assert len(messages) == 2  # one for each of the two repeated constraints (x and y of B)
    for message in messages:
        assert "redundant constraints among pairs B1, B2, B3" in message and "counts -1" in message
