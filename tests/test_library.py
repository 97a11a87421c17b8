"""The mechanism library (planardyn.library): shipped files, assembly, `planardyn check`,
passive motion under gravity with energy conserved.

The expected mobilities are Chebyshev-Grubler counts done by hand in each constructor's
docstring (3n - 2p), and for the double parallelogram the rank count (one redundant pair
constraint: Grubler says 0, the mechanism moves with 1).
"""

from __future__ import annotations

import copy
import math
import warnings
from pathlib import Path

import numpy as np
import planardyn as pd
import pytest
import yaml
from planardyn import library as lib
from planardyn.cli import main as cli_main

ROOT = Path(__file__).resolve().parents[1]

# Passive motion, 1 s under gravity, at a tight tolerance: the energy balance T + V - E0 must
# stay below ENERGY_REL of the largest kinetic energy reached. dop853 at rtol 1e-11 keeps the
# local errors near 1e-11, which summed over ~1000 steps stays well under 1e-8.
ENERGY_REL = 1e-8
RTOL, ATOL = 1e-11, 1e-13

# stem -> (mobility, coordinates): each from the constructor's docstring.
EXPECTED = {
    "four-bar": (1, ["theta1"]),
    "slider-crank": (1, ["theta"]),
    "slider-crank-slider-driven": (1, ["s"]),
    "five-bar-5r": (2, ["theta1", "theta2"]),
    "biglide": (2, ["s1", "s2"]),
    "3-rrr": (3, ["theta1", "theta2", "theta3"]),
    "3-rpr": (3, ["L1", "L2", "L3"]),
    "3-prr": (3, ["s1", "s2", "s3"]),
    "watt-six-bar": (1, ["theta1"]),
    "stephenson-six-bar": (1, ["theta1"]),
    "double-parallelogram": (1, ["theta1"]),
}
STEMS = list(lib.LIBRARY)


def build(stem: str) -> pd.Mechanism:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the double parallelogram's redundancy warning
        return pd.from_dict(lib.LIBRARY[stem]())



def test_every_library_mechanism_has_an_expectation_and_a_file():
    assert sorted(EXPECTED) == sorted(STEMS)
    assert sorted(p.stem for p in lib.LIBRARY_DIR.glob("*.yaml")) == sorted(STEMS)


@pytest.mark.parametrize("stem", STEMS)
def test_shipped_file_is_the_constructor_output(stem):
    path = lib.LIBRARY_DIR / f"{stem}.yaml"
    model = lib.LIBRARY[stem]()
    text = path.read_text()
    assert text == lib.model_text(model, lib.file_header(stem)), "regenerate: python -m planardyn.library"
    assert yaml.safe_load(text) == model  # the writer round-trips through a YAML 1.1 reader
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert pd.load(path) == build(stem)


def test_write_model_takes_a_mechanism_or_a_dict(tmp_path):
    mech = lib.four_bar(theta=1.0)
    p1 = lib.write_model(mech, tmp_path / "a.yaml")
    p2 = lib.write_model(lib.four_bar_model(theta=1.0), tmp_path / "b.yaml")
    assert pd.load(p1) == mech == pd.load(p2)


@pytest.mark.parametrize("stem", [s for s in STEMS if s != "double-parallelogram"])
def test_loads_and_check_reports_its_mobility(stem, capsys, tmp_path):
    mech = build(stem)
    dof, names = EXPECTED[stem]
    assert mech.dof == dof and mech.coordinate_names == names
    # The drawing closes: the position analysis at the drawn inputs returns the drawing.
    np.testing.assert_allclose(mech.assemble(mech.drawn_q), mech.x0, atol=1e-12 * mech.scale)
    assert cli_main(["check", str(lib.LIBRARY_DIR / f"{stem}.yaml")]) == 0
    out = capsys.readouterr().out
    assert f"3n - rank = {3 * mech.n_bodies} - {3 * mech.n_bodies - dof} = {dof}" in out
    assert "no redundant constraints" in out


def _energy_drift(mech: pd.Mechanism, t_end: float = 1.0) -> tuple[float, pd.SimulationResult]:
    res = mech.simulate(t_end=t_end, method="dop853", rtol=RTOL, atol=ATOL)
    assert res.success, res.message
    assert res.t[-1] == pytest.approx(t_end)
    return res.energy.drift / res.energy.kinetic.max(), res


@pytest.mark.parametrize("stem", [s for s in STEMS if s != "double-parallelogram"])
def test_passive_motion_under_gravity_conserves_energy(stem):
    mech = build(stem)
    assert np.linalg.norm(mech.gravity) == pytest.approx(9.81)
    assert not mech.to_dict().get("drives") and not mech.to_dict().get("loads")
    rel, res = _energy_drift(mech)
    assert res.energy.kinetic.max() > 1e-3  # it really moves
    assert rel < ENERGY_REL, f"relative energy drift {rel:.3g}"
    assert np.max(res.residual) < 1e-9


def test_double_parallelogram_redundancy_is_explained_by_the_loader():
    """Grubler 3*4 - 2*6 = 0, yet it moves: the loader accepts it, warning which pairs are
    redundant."""
    model = lib.double_parallelogram_model()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mech = pd.from_dict(model)
    assert mech.dof == 1
    msg = " ".join(str(w.message) for w in caught)
    assert "redundant" in msg
    for name in ("ground_crank3", "crank3_coupler", "ground_crank1"):
        assert name in msg


def test_double_parallelogram_simulates():
    mech = build("double-parallelogram")
    rel, res = _energy_drift(mech)
    assert rel < ENERGY_REL
    # All three cranks stay parallel: every crank angle equals theta1 (parallelograms).
    phis = res.x[:, [2, 5, 8]]
    np.testing.assert_allclose(phis - phis[:, :1], 0.0, atol=1e-9)


def test_andrews_squeezer_loads_checks_and_conserves_energy(capsys):
    mech = lib.andrews_squeezer()
    assert mech.dof == 1 and mech.n_bodies == 7
    assert cli_main(["check", str(lib.MODELS_DIR / "andrews-squeezer.yaml")]) == 0
    assert "3n - rank = 21 - 20 = 1" in capsys.readouterr().out
    # Its own benchmark run is driven; passive motion under gravity: drop the drive and turn
    # gravity on (the stiff spring stays: it is conservative).
    model = mech.to_dict()
    model["drives"] = []
    model["gravity"] = [0.0, -9.81]
    passive = pd.from_dict(model)
    res = passive.simulate(t_end=1.0, method="dop853", rtol=RTOL, atol=ATOL)
    assert res.success, res.message
    assert res.energy.drift / res.energy.kinetic.max() < ENERGY_REL


# ----------------------------------------------------------------------------- geometry


def test_circle_intersection_side_and_failure():
    left = lib.circle_intersection((0, 0), 1.0, (1, 0), 1.0, +1)
    right = lib.circle_intersection((0, 0), 1.0, (1, 0), 1.0, -1)
    assert left == pytest.approx((0.5, math.sqrt(3) / 2)) and right == pytest.approx((0.5, -math.sqrt(3) / 2))
    with pytest.raises(ValueError, match="do not meet"):
        lib.circle_intersection((0, 0), 1.0, (3, 0), 1.0, 1)
    with pytest.raises(ValueError, match="mode"):
        lib.circle_intersection((0, 0), 1.0, (1, 0), 1.0, 0)


def test_modes_choose_the_assembly():
    up, down = lib.five_bar_model(mode=1), lib.five_bar_model(mode=-1)
    assert up["points"]["P"][1] > 0.17 > down["points"]["P"][1]
    # Both are valid drawings of the same robot: same lengths, other working mode.
    assert lib.five_bar(mode=-1).dof == 2
    m = lib.three_rrr_model(modes=(1, -1, 1))
    assert m["coordinates"][1]["value"] != lib.three_rrr_model()["coordinates"][1]["value"]
    with pytest.raises(ValueError, match="cannot assemble"):
        lib.four_bar_model(crank=0.1, coupler=0.2, rocker=0.2, ground=1.0)


def test_four_bar_defaults_are_the_benchmark_drawing():
    # four-bar-gravity.yaml: the same points (its masses differ: inertias given there).
    bench = yaml.safe_load((lib.MODELS_DIR / "four-bar-gravity.yaml").read_text())
    ours = lib.four_bar_model()
    for p in "OADB":
        assert ours["points"][p] == pytest.approx(bench["points"][p], abs=1e-15)


def test_grashof():
    assert lib.grashof(1.0, 0.5, 1.2, 1.0)  # the default crank-rocker
    assert not lib.grashof(1.0, 0.9, 0.3, 0.35)


def test_docs_pictures_exist():
    for stem in STEMS:
        assert (ROOT / "docs" / "img" / f"library-{stem}.png").is_file(), stem


def _masses_times(model, k):
    model = copy.deepcopy(model)
    for body in model["bodies"].values():
        for part in [body, *body.get("parts", [])]:
            for field in ("mass", "inertia"):
                if field in part:
                    part[field] *= k
    return model


def test_masses_scaled_together_leave_the_motion_unchanged():
    # Under gravity alone, q(t) does not depend on the masses' common factor: the motion at
    # k = 1e12 is the one at k = 1, to the integration's tolerance (rtol 1e-10 over 0.01 s).
    # Before 6df075e (a slider's group length taken from an ulp's offset of its centre of
    # mass) every evaluation failed from t = 0 for k = 1e11 .. 1e15 (s15-sweep's find).
    model = lib.three_prr_model()
    base = pd.from_dict(model).simulate(t_end=0.01, output_dt=0.001, rtol=1e-10)
    heavy = pd.from_dict(_masses_times(model, 1e12)).simulate(t_end=0.01, output_dt=0.001, rtol=1e-10)
    assert heavy.success, heavy.message
    np.testing.assert_allclose(heavy.q, base.q, rtol=0, atol=1e-9)
