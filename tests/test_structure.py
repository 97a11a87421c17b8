"""Structural analysis (planardyn.structure) of every library mechanism, with the expected
answer derived by hand in a comment; the constraint Jacobian from Rust against the
velocity analogues, and its rank and self-stresses against an independent computation from
the drawing in this file.
"""

from __future__ import annotations

import itertools
import math
import warnings

import numpy as np
import planardyn as pd
import pytest
from planardyn import _core, structure
from planardyn import library as lib


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
    xy = {"J5": [0.0, 0.0], "J6": [2.0, 0.0], "J7": [2.3, 1.1], "J1": [0.2, 1.0], "J3": [0.9, 0.4],
          "J2": [1.1, 1.9], "J4": [1.8, 1.3]}
    links = {"T1": ["J5", "J1", "J3"], "T2": ["J7", "J2", "J4"], "b1": ["J1", "J2"], "b2": ["J3", "J4"],
             "b4": ["J6", "J7"]}
    joints = [("J5", "ground", "T1"), ("J6", "ground", "b4"), ("J7", "b4", "T2"), ("J1", "T1", "b1"),
              ("J2", "b1", "T2"), ("J3", "T1", "b2"), ("J4", "b2", "T2")]
    model = {
        "name": "Stephenson chain on a binary link", "points": xy, "ground": ["J5", "J6"],
        "bodies": {b: {"points": p, "uniform_bar": p[:2], "mass": 1.0} for b, p in links.items()},
        "pairs": [{"type": "revolute", "name": n, "at": n, "bodies": [a, b]} for n, a, b in joints],
        "coordinates": [{"name": "q", "pair": "J6", "value": 0.0}],
    }
    s = structure.analyse(model)
    assert s.load_error is None and s.input_links == ("b4",) and s.left_over == ()
    (g,) = s.groups
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


def drawn_jacobian(model) -> np.ndarray:
    """Scaled Phi_x at the drawing from the model dict alone, each body's reference point its
    first point (any reference gives the same rank and the same null space of Phi_x^T: a
    change of reference is an invertible column change). Revolute rows: d(P_b - P_a);
    prismatic rows: d(phi_b - phi_a) and n . d(P_b - P_a), n the guide's normal. Metre rows
    / L, translation columns * L."""
    pts = {k: (float(v[0]), float(v[1])) for k, v in model["points"].items()}
    bodies = list(model["bodies"])
    col = {b: 3 * i for i, b in enumerate(bodies)}
    ref = {b: pts[model["bodies"][b]["points"][0]] for b in bodies}
    L = max((math.dist(p, q) for p, q in itertools.combinations(pts.values(), 2)), default=1.0) or 1.0
    J = np.zeros((2 * len(model["pairs"]), 3 * len(bodies)))

    def point_rows(link, P, sign):
        g = np.zeros((2, 3 * len(bodies)))
        if link != "ground":
            c, r = col[link], ref[link]
            g[:, c : c + 2] = sign * np.eye(2) * L
            g[:, c + 2] = sign * np.array([-(P[1] - r[1]), P[0] - r[0]])
        return g

    for k, pr in enumerate(model["pairs"]):
        a, b = pr["bodies"]
        P = pts[pr["at"]]
        d = point_rows(b, P, 1.0) + point_rows(a, P, -1.0)
        if pr["type"] == "revolute":
            J[2 * k : 2 * k + 2] = d / L
        else:
            axis = pr.get("axis") or np.subtract(pts[pr["along"][1]], pts[pr["along"][0]])
            t = np.asarray(axis, dtype=float) / np.hypot(*axis)
            for link, sign in ((b, 1.0), (a, -1.0)):
                if link != "ground":
                    J[2 * k, col[link] + 2] = sign
            J[2 * k + 1] = np.array([-t[1], t[0]]) @ d / L
    return J


def stressed_pairs(J: np.ndarray, names) -> set[str]:
    """The pairs with a share of the left null space of J (numpy's SVD, the core's 1e-9)."""
    U, s, _ = np.linalg.svd(J)
    rank = int(np.sum(s > 1e-9 * max(s.max(), 1.0)))
    null = U[:, rank:]
    share = np.hypot(np.linalg.norm(null[0::2], axis=1), np.linalg.norm(null[1::2], axis=1))
    return {n for n, w in zip(names, share) if w > 1e-6}


@pytest.mark.parametrize("stem", list(EXPECTED))
def test_singular_values_and_an_independent_jacobian_agree(stem):
    mech = build(stem)
    Js = _core.constraint_jacobian(mech._native, mech.x0, True)
    s = structure.analyse(mech)
    np.testing.assert_allclose(s.singular_values, np.sort(np.linalg.svd(Js, compute_uv=False)), atol=1e-12)
    # Independent computation from the drawing (other body reference points): same rank
    # and the same pairs in the self-stresses.
    J2 = drawn_jacobian(lib.LIBRARY[stem]())
    assert s.rank == np.linalg.matrix_rank(J2, tol=1e-9 * max(np.linalg.norm(J2, 2), 1.0))
    assert {p for st in s.redundant_pairs for p in st} == stressed_pairs(J2, mech.pair_names)


def test_analyse_a_model_the_loader_refuses():
    # A four-bar with a spare coordinate: the loader refuses (mobility mismatch); the
    # analysis still runs from the drawing and reports the loader's message.
    model = lib.four_bar_model()
    model["coordinates"].append({"name": "extra", "pair": "ground_rocker", "value": 0.0})
    s = structure.analyse(model)
    assert s.load_error and "coordinates" in s.load_error
    assert (s.grubler, s.mobility, s.redundant) == (1, 1, 0)
    assert "the loader refuses this model" in structure.report(model)
