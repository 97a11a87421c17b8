"""The loader's work stays near-linear in its input: many points and deep nesting.

The characteristic length L (the points' diameter) was an all-pairs scan, quadratic in the
number of points; the YAML parser is quadratic in the nesting depth. Both are checked by
what they return, not by a clock: L against the known diameter of the added points, the
nesting error against its exact location.
"""

from __future__ import annotations

import math

import planardyn as pd
import pytest
import yaml
from planardyn import ModelError

MODELS = "examples/models"


def test_many_unused_points_give_their_exact_diameter():
    # 20,000 points on a circle of radius 5 m around the five-bar: the diameter is then
    # 10 m to within the spacing's sagitta, 5 (1 - cos(pi/20000)) = 6e-8 m.
    spec = yaml.safe_load(open(f"{MODELS}/five-bar.yaml"))
    n = 20_000
    for i in range(n):
        a = 2 * math.pi * i / n
        spec["points"][f"u{i}"] = [5 * math.cos(a), 5 * math.sin(a)]
    mech = pd.from_dict(spec)
    assert mech.scale == pytest.approx(10.0, abs=1e-7)


@pytest.mark.parametrize("depth", [64, 100_000])
def test_deep_nesting_is_refused_at_its_place(depth):
    text = "name: x\npoints: " + "[" * depth + "]" * depth
    with pytest.raises(ModelError) as err:
        pd.loads(text)
    # The top-level mapping is one level, so the 64th bracket (column 9 + 63) is the 65th.
    assert "line 2 column 72" in str(err.value)
    assert "nests deeper than 64 levels" in str(err.value)
