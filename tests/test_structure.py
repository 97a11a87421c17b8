"""Structural analysis (planardyn.structure) of every library mechanism, with the expected
answer derived by hand in a comment; the constraint Jacobian from Rust against the
velocity analogues and against an independent Python computation from the drawing.
"""

from __future__ import annotations

import warnings

import numpy as np
import planardyn as pd
import pytest
from planardyn import _core, structure
from planardyn import library as lib
from planardyn.structure import _assur, _drawn_jacobian, _Pair, _pairs_of, _rank_and_null, _self_stresses


def build(stem: str) -> pd.Mechanism:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return pd.from_dict(lib.LIBRARY[stem]())


def dyad(kind, *links):
    return (2, 2, kind, links)


# stem -> (grubler, mobility, loops, input links, relative inputs, groups as
# (class, order, kind, links)). Derivations (inputs locked, smallest zero-mobility set first):
EXPECTED = {
    # n=3, p=4: 3*3-8 = 1; one loop (4 - 4 + 1). Crank on ground; coupler+rocker: pairs A
    # (to the crank), B (inner), D (to ground) = 3, 3*2 - 2*3 = 0: an RRR dyad.
    "four-bar": (1, 1, 1, ("crank",), (), [dyad("RRR", "coupler", "rocker")]),
    # Crank input; rod + slider: crank pin R (outer), wrist pin R (inner), guide P (outer): RRP.
    "slider-crank": (1, 1, 1, ("crank",), (), [dyad("RRP", "rod", "slider")]),
    # Slider input (prismatic to ground); crank + rod: crank pivot R, crank pin R, wrist pin R.
    "slider-crank-slider-driven": (1, 1, 1, ("slider",), (), [dyad("RRR", "crank", "rod")]),
    # n=4, p=5: 12-10 = 2; two proximal input links; the distal links form one RRR dyad.
    "five-bar-5r": (2, 2, 1, ("proximal1", "proximal2"), (), [dyad("RRR", "distal1", "distal2")]),
    # Two sliders are the input links; the bars: hinge R, tip R, hinge R.
    "biglide": (2, 2, 1, ("slider1", "slider2"), (), [dyad("RRR", "bar1", "bar2")]),
    # n=7, p=9: 21-18 = 3; loops 9 - 8 + 1 = 2. No two free links close with 3 pairs (the
    # platform touches no fixed link), so k=4: three distal links + platform, 6 pairs,
    # 12 - 12 = 0: a triad (the platform is the ternary base link), class III, order 3.
    "3-rrr": (3, 3, 2, ("proximal1", "proximal2", "proximal3"), (),
              [(3, 3, "6R", ("distal1", "distal2", "distal3", "platform"))]),
    # Relative inputs: barrel_i + rod_i locked into one rigid leg; legs + platform: the same triad.
    "3-rpr": (3, 3, 2, (), ("barrel1+rod1 (leg1)", "barrel2+rod2 (leg2)", "barrel3+rod3 (leg3)"),
              [(3, 3, "6R", ("barrel1+rod1", "barrel2+rod2", "barrel3+rod3", "platform"))]),
    # Sliders on ground are the input links; distal links + platform: the same triad.
    "3-prr": (3, 3, 2, ("slider1", "slider2", "slider3"), (),
              [(3, 3, "6R", ("distal1", "distal2", "distal3", "platform"))]),
    # n=5, p=7: 15-14 = 1; loops 7 - 6 + 1 = 2. Two four-bars in series: two RRR dyads.
    "watt-six-bar": (1, 1, 2, ("crank",), (),
                     [dyad("RRR", "coupler1", "rocker"), dyad("RRR", "coupler2", "output")]),
    # Crank input; no dyad closes (link1+triangle has 3 pairs only with link2 or link3 too),
    # so the triangle and its three binary links are one triad: class III, order 3.
    "stephenson-six-bar": (1, 1, 2, ("crank",), (),
                           [(3, 3, "6R", ("link1", "link2", "link3", "triangle"))]),
    # n=4, p=6: Grubler 0; rank 11 so mobility 1, one redundant constraint; loops 6-5+1 = 2.
    # crank1 input; crank2 + coupler an RRR dyad; crank3 left: 3*1 - 2*2 = -1 (over-constrained).
    "double-parallelogram": (0, 1, 2, ("crank1",), (), [dyad("RRR", "crank2", "coupler")]),
}


def groups_of(s: structure.Structure):
    return [(g.group_class, g.order, g.kind, g.links) for g in s.groups]


@pytest.mark.parametrize("stem", list(EXPECTED))
def test_library_structure(stem):
    grubler, mobility, loops, inputs, relative, groups = EXPECTED[stem]
    mech = build(stem)
    s = structure.analyse(mech)
    assert (s.grubler, s.mobility, s.n_loops, len(s.loops)) == (grubler, mobility, loops, loops)
    assert s.mobility == mech.dof
    assert s.input_links == inputs and s.relative_inputs == relative
    assert groups_of(s) == groups
    assert s.sigma_min is not None and s.sigma_min > 0
    assert s.connected
    if stem == "double-parallelogram":
        assert s.redundant == 1 and s.left_over == ("crank3",) and s.left_over_mobility == -1
        # The self-stress: cranks 1 and 3 pull, crank 2 pushes twice as hard: every pair.
        assert set(s.redundant_pairs[0]) == set(mech.pair_names)
        assert "redundant constraints: 1" in structure.report(mech)
    else:
        assert s.redundant == 0 and s.redundant_pairs == () and s.left_over == ()
        assert "no redundant constraints" in structure.report(mech)


def test_andrews_squeezer_structure():
    # n=7, p=10: 21-20 = 1; loops 10 - 8 + 1 = 3. Crank b1; b2+b3 (pairs P, E, B) an RRR
    # dyad; then b4+b5 (E on b2, G, A) and b6+b7 (E on b2, H, A) two more RRR dyads.
    s = structure.analyse(lib.andrews_squeezer())
    assert (s.grubler, s.mobility, s.n_loops) == (1, 1, 3)
    assert s.input_links == ("b1",)
    assert groups_of(s) == [dyad("RRR", "b2", "b3"), dyad("RRR", "b4", "b5"), dyad("RRR", "b6", "b7")]


def test_loops_close():
    # Each loop path starts and ends at one link and alternates links and pairs.
    s = structure.analyse(build("3-rrr"))
    names = set(s.links)
    for lp in s.loops:
        assert lp.path[0] == lp.path[-1] and lp.closing_pair in lp.path
        assert all(x in names for x in lp.path[::2])


def test_class_iv_group_from_topology():
    """Stephenson's chain with a binary link as ground: T1-b1-T2-b2 is a closed four-link
    contour joined to the fixed links at two pairs: class IV, order 2 (Artobolevsky)."""
    P = lambda n, a, b: _Pair(n, "revolute", a, b, n, None)  # noqa: E731
    pairs = [P("J5", "ground", "T1"), P("J6", "ground", "b4"), P("J7", "b4", "T2"), P("J1", "T1", "b1"),
             P("J2", "b1", "T2"), P("J3", "T1", "b2"), P("J4", "b2", "T2")]
    inputs, relative, groups, left, _ = _assur(["b4", "T1", "T2", "b1", "b2"], pairs, ["J6"])
    assert inputs == ("b4",) and left == ()
    (g,) = groups
    assert (g.group_class, g.order, sorted(g.links), sorted(g.outer_pairs)) == (4, 2, ["T1", "T2", "b1", "b2"], ["J5", "J7"])


# ----------------------------------------------------------------------------- Phi_x


@pytest.mark.parametrize("stem", list(EXPECTED))
def test_constraint_jacobian_annihilates_the_velocity_analogues(stem):
    mech = build(stem)
    k = mech.kinematics(mech.q0)
    J = _core.constraint_jacobian(mech._native, k["x"])
    assert J.shape == (2 * len(mech.pair_names), 3 * mech.n_bodies)
    U = k["u"].reshape(3 * mech.n_bodies, mech.dof)
    np.testing.assert_allclose(J @ U, 0.0, atol=1e-10 * np.abs(J).max() * np.abs(U).max())


@pytest.mark.parametrize("stem", list(EXPECTED))
def test_singular_values_and_the_python_jacobian_agree(stem):
    mech = build(stem)
    Js = _core.constraint_jacobian(mech._native, mech.x0, True)
    sv = _core.constraint_singular_values(mech._native, mech.x0)
    np.testing.assert_allclose(sv, np.sort(np.linalg.svd(Js, compute_uv=False)), atol=1e-12)
    # Independent computation from the drawing (other body reference points): same rank
    # and the same pairs in each self-stress.
    model = lib.LIBRARY[stem]()
    pairs = _pairs_of(model)
    r1, _, n1 = _rank_and_null(Js)
    r2, _, n2 = _rank_and_null(_drawn_jacobian(model, pairs))
    assert r1 == r2
    assert _self_stresses(n1, pairs) == _self_stresses(n2, pairs)


def test_analyse_a_model_the_loader_refuses():
    # A four-bar with a spare coordinate: the loader refuses (mobility mismatch); the
    # analysis still runs from the drawing and reports the loader's message.
    model = lib.four_bar_model()
    model["coordinates"].append({"name": "extra", "pair": "ground_rocker", "value": 0.0})
    s = structure.analyse(model)
    assert s.load_error and "coordinates" in s.load_error
    assert (s.grubler, s.mobility, s.redundant) == (1, 1, 0)
    assert "the loader refuses this model" in structure.report(model)
