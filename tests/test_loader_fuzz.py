"""Hardened loading and property tests on random mechanisms (hypothesis).

1. Fuzzing the loader: random mutations of valid model dicts (a key deleted, a value of
   another type, random strings, negative/NaN/huge numbers, duplicate names) and random YAML
   text must either load or raise ``ModelError``/``PlanardynError`` whose message names the
   source and a field -- never another exception, never an internal error (a Rust panic is
   turned into ``PlanardynError('internal error ...')``: that is a bug here).
   ``PLANARDYN_FUZZ_EXAMPLES=20000 pytest tests/test_loader_fuzz.py -k fuzz`` runs a longer
   campaign; inputs worth keeping are in ``tests/fuzz_corpus/`` and replayed every run.
2. Random four-bars and five-bars from the library constructors (Grashof crank-rockers,
   assemblable five-bars): the drawing closes, energy is conserved over 1 s of passive
   motion under gravity, and q(t) does not depend on the drawing frame or on the order in
   which points, bodies and pairs are listed.
"""

from __future__ import annotations

import copy
import json
import math
import os
import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import planardyn as pd
import pytest
import yaml
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from planardyn import library as lib

ROOT = Path(__file__).resolve().parents[1]
CORPUS = Path(__file__).resolve().parent / "fuzz_corpus"
FUZZ_EXAMPLES = int(os.environ.get("PLANARDYN_FUZZ_EXAMPLES", "300"))

# Valid models to mutate: library mechanisms (revolute and prismatic pairs, parts, relative
# inputs) and shipped files with drives, loads, tables and simulate settings.
BASES: list[dict[str, Any]] = [
    lib.four_bar_model(),
    lib.slider_crank_model(),
    lib.three_rpr_model(),
    lib.watt_six_bar_model(),
    yaml.safe_load((ROOT / "examples/models/five-bar.yaml").read_text()),
    yaml.safe_load((ROOT / "examples/models/hydraulic-boom.yaml").read_text()),
    yaml.safe_load((ROOT / "examples/models/slider-crank.yaml").read_text()),
]


#: Rust names that must not reach a user (serde's own words for the schema's types).
JARGON = ("Spec", "f64", "usize", "struct ", "enum ")


def check_outcome(call) -> str:
    """Run a load; return 'ok' or the error's path. Fail on anything but a model error
    that names its source, a location and a fix."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            mech = call()
        except pd.ModelError as e:
            msg = str(e)
            assert "internal error" not in msg, msg
            # The location: a field path ('bodies.crank.mass', 'pairs[2].at'), or where no
            # field can be named (a syntax error, a document that is not a mapping) the
            # parser's 'line L column C'.
            assert e.source and e.path, msg
            message = msg.removeprefix(f"{e.source}: {e.path}: ")
            assert message != msg and message.strip(), msg
            ours = "".join(re.split(r'["`]', message)[::2])  # the user's own text is quoted
            assert not any(w in ours for w in JARGON), msg
            return e.path
        except pd.PlanardynError as e:
            assert "internal error" not in str(e), str(e)
            return type(e).__name__
    assert isinstance(mech, pd.Mechanism)
    return "ok"


# ----------------------------------------------------------------------------- mutations

def paths(obj: Any, prefix: tuple = ()) -> list[tuple]:
    """Every path (tuple of keys/indices) into a nested dict/list, the root excluded."""
    out = []
    if isinstance(obj, dict):
        for k, v in obj.items():
            out.append(prefix + (k,))
            out += paths(v, prefix + (k,))
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            out.append(prefix + (i,))
            out += paths(v, prefix + (i,))
    return out


def get(obj: Any, path: tuple) -> Any:
    for k in path:
        obj = obj[k]
    return obj


numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -1.0, -1e-300, 1e300, 1e308, -1e308, 5e-324, float("nan"), float("inf")]),
    st.integers(min_value=-(2**70), max_value=2**70),
)
scalars = st.one_of(numbers, st.text(max_size=12), st.booleans(), st.none())
values = st.recursive(scalars, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                       st.dictionaries(st.text(max_size=6), inner, max_size=3)),
                      max_leaves=6)


@st.composite
def mutated_models(draw) -> dict[str, Any]:
    model = copy.deepcopy(draw(st.sampled_from(BASES)))
    for _ in range(draw(st.integers(1, 3))):
        all_paths = paths(model)
        if not all_paths:
            break
        path = draw(st.sampled_from(all_paths))
        parent, key = get(model, path[:-1]), path[-1]
        action = draw(st.sampled_from(["delete", "replace", "number", "string", "duplicate", "swap"]))
        if action == "delete":
            del parent[key]
        elif action == "replace":
            parent[key] = draw(values)
        elif action == "number":
            parent[key] = draw(numbers)
        elif action == "string":
            parent[key] = draw(st.one_of(st.text(max_size=20), st.sampled_from(
                ["ground", "", "O", "A", "revolute", "prismatic", "yes", "null", "1e-6", "P\u00e9"])))
        elif action == "duplicate" and isinstance(parent, list) and parent:
            parent.append(copy.deepcopy(parent[draw(st.integers(0, len(parent) - 1))]))
        elif action == "duplicate" and isinstance(parent, dict):
            # Another entry's name or value under this key.
            other = draw(st.sampled_from(list(parent)))
            parent[key] = copy.deepcopy(parent[other])
        elif action == "swap" and isinstance(parent, dict) and len(parent) > 1:
            other = draw(st.sampled_from(list(parent)))
            parent[key], parent[other] = parent[other], parent[key]
    return model


yaml_texts = st.one_of(
    st.text(max_size=200),
    # YAML-looking text: keys of the schema, brackets, colons, indentation, tabs.
    st.lists(st.sampled_from(["name: x\n", "points:\n", "  O: [0, 0]\n", "  A: [1, 0]\n", "ground: [O]\n",
                              "bodies:\n", "  b: {points: [O, A], uniform_bar: [O, A], mass: 1}\n",
                              "pairs:\n", "  - {type: revolute, name: r, at: O, bodies: [ground, b]}\n",
                              "coordinates:\n", "  - {name: q, pair: r, value: 0}\n", "\t", "[", "]", "{", "}",
                              ": ", "- ", "&a ", "*a", "!!float ", "~", ".nan", "-.inf", "1e999", "  O: [0, 0]\n",
                              "'", '"', "\n", "#"]), max_size=25).map("".join),
)


def dump(model: dict) -> str:
    return json.dumps(model, allow_nan=True)


@settings(max_examples=FUZZ_EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck))
@given(mutated_models())
def test_fuzz_mutated_models(model):
    # Far starts (q0 1e300 from the drawing) and huge points (1e308 m) must be refused, not
    # hang the loader (tests/fuzz_corpus/far-q0.yaml, hang-huge-point-prismatic.yaml).
    check_outcome(lambda: pd.from_dict(model))
    # The same through YAML text (PyYAML's emitter; NaN and inf become .nan and .inf).
    check_outcome(lambda: pd.loads(yaml.safe_dump(model), "yaml", "<fuzz>"))


@settings(max_examples=FUZZ_EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck))
@given(yaml_texts)
def test_fuzz_random_yaml_text(text):
    check_outcome(lambda: pd.loads(text, "yaml", "<fuzz>"))


def test_fuzz_duplicate_keys_in_text():
    text = lib.model_text(lib.four_bar_model())
    dup_point = text.replace("  D: ", "  O: [9.0, 9.0]\n  D: ", 1)
    assert check_outcome(lambda: pd.loads(dup_point)).startswith("points")
    model = lib.four_bar_model()
    model["pairs"][1]["name"] = model["pairs"][0]["name"]
    assert check_outcome(lambda: pd.from_dict(model)).startswith("pairs[1]")


@pytest.mark.parametrize("path", sorted(CORPUS.glob("*.yaml")), ids=lambda p: p.name)
def test_fuzz_corpus_replays(path):
    """Inputs kept from fuzz runs (see tests/fuzz_corpus/README.md); each file's first line
    says what the loader must do: '# expect: ok' or '# expect: error <path>'."""
    text = path.read_text()
    expect = text.splitlines()[0].removeprefix("# expect:").strip()
    got = check_outcome(lambda: pd.loads(text, "yaml", path.name))
    assert got == ("ok" if expect == "ok" else expect.removeprefix("error ").strip())


# ----------------------------------------------------------------------------- located errors

MAPPING_FIX = ("a model file must be a mapping with the keys name, points, ground, bodies, pairs and coordinates: "
               "see `planardyn docs model-format`")
YAML_FIX = "the text is not valid YAML: check the indentation, brackets, quotes and colons there"


def refused(call) -> pd.ModelError:
    with pytest.raises(pd.ModelError) as info:
        call()
    return info.value


@pytest.mark.parametrize(("text", "path", "message"), [
    ("# a comment\n;\n", "line 2 column 1", f'the model is string ";", not a mapping; {MAPPING_FIX}'),
    ("[1, 2]", "line 1 column 1", f"the model is sequence, not a mapping; {MAPPING_FIX}"),
    (",./;[]", "line 1 column 1", f"did not find expected node content, while parsing a block node; {YAML_FIX}"),
    ("*a", "line 1 column 1",
     "unknown anchor; an alias `*name` needs an anchor `&name` before it: add the anchor or write the value out"),
    ("name: x\n!!float ~}~~\n", "line 3 column 1", f"could not find expected ':', while scanning a simple key; {YAML_FIX}"),
])
def test_an_error_no_field_can_name_gives_line_and_column(text, path, message):
    e = refused(lambda: pd.loads(text, "yaml", "m.yaml"))
    assert (e.source, e.path) == ("m.yaml", path)
    assert str(e) == f"m.yaml: {path}: {message}"


def test_a_missing_top_level_field_is_its_own_path():
    model = {k: v for k, v in lib.four_bar_model().items() if k != "name"}
    e = refused(lambda: pd.from_dict(model))
    assert e.path == "name"
    assert str(e) == "<dict>: name: missing field `name`; add it (see `planardyn docs model-format`)"
    del model["coordinates"][0]["value"]
    model["name"] = "x"
    assert refused(lambda: pd.from_dict(model)).path == "coordinates[0].value"


def test_a_dicts_errors_name_the_field_path_and_no_line():
    # A dict reaches the loader as JSON text its user never wrote: no "line 1 column N" of it
    # (on main every error of from_dict had one), the field path alone, the checks' and the
    # parser's alike; a NaN (json.dumps writes it) is named for what it is.
    model = lib.four_bar_model()
    model["bodies"]["rocker"]["mass"] = -1.0
    assert str(refused(lambda: pd.from_dict(model))) == "<dict>: bodies.rocker.mass: mass must be > 0 kg, got -1"
    model["bodies"]["rocker"]["mass"] = float("nan")
    assert str(refused(lambda: pd.from_dict(model))) == (
        "<dict>: bodies.rocker.mass: not a finite number; give a finite number (NaN and infinities are not model values)")
    model["bodies"]["rocker"]["mass"] = "heavy"
    e = refused(lambda: pd.from_dict(model))
    assert e.path == "bodies.rocker.mass" and "line" not in str(e), str(e)


def test_a_file_not_in_utf8_is_located_at_the_first_bad_byte(tmp_path):
    path = tmp_path / "latin1.yaml"
    path.write_bytes(lib.model_text(lib.four_bar_model()).replace("  D: ", "  D\u00e9: ").encode("latin-1"))
    e = refused(lambda: pd.load(path))
    line = lib.model_text(lib.four_bar_model()).splitlines().index("  D: [1.0, 0.0]") + 1
    assert str(e) == f"{path}: line {line} column 4: the file is not UTF-8 text; save it as UTF-8"


# ----------------------------------------------------------------------------- random mechanisms

# Property tests of the integrator's invariants: tolerances as in tests/test_library.py.
RTOL, ATOL = 1e-11, 1e-13
ENERGY_REL = 1e-8
#: q(t) from two equivalent descriptions agree to this (rad): rounding of the drawing (1e-16)
#: grown by 1 s of integration at rtol 1e-11.
SAME_Q = 1e-9


@st.composite
def four_bars(draw) -> dict[str, Any]:
    """Grashof crank-rockers (the crank the shortest link, next to the ground): the crank
    turns fully, so every crank angle assembles."""
    crank = draw(st.floats(0.1, 0.4))
    coupler = draw(st.floats(0.5, 1.5))
    rocker = draw(st.floats(0.5, 1.5))
    assume(lib.grashof(1.0, crank, coupler, rocker) and crank < min(coupler, rocker))
    # Stay away from the folded limits (s + l = p + q is a change point).
    links = sorted([1.0, crank, coupler, rocker])
    assume(links[1] + links[2] - links[0] - links[3] > 0.05)
    return lib.four_bar_model(crank=crank, coupler=coupler, rocker=rocker, theta=draw(st.floats(0, 2 * math.pi)),
                              mode=draw(st.sampled_from([1, -1])))


@st.composite
def five_bars(draw) -> dict[str, Any]:
    base = draw(st.floats(0.1, 0.3))
    proximal = draw(st.floats(0.15, 0.3))
    th1, th2 = draw(st.floats(math.pi / 2, math.pi)), draw(st.floats(0.0, math.pi / 2))
    b1 = np.array([-base / 2 + proximal * math.cos(th1), proximal * math.sin(th1)])
    b2 = np.array([base / 2 + proximal * math.cos(th2), proximal * math.sin(th2)])
    half = float(np.linalg.norm(b2 - b1)) / 2
    distal = half * draw(st.floats(1.2, 2.0))  # the distal links reach each other, not folded
    return lib.five_bar_model(base=base, proximal=proximal, distal=distal, theta1=th1, theta2=th2,
                              mode=draw(st.sampled_from([1, -1])))


mechanisms = st.one_of(four_bars(), five_bars())


def q_of(model: dict) -> np.ndarray:
    """q(t) on a grid: 1 s for a four-bar; 0.5 s for a five-bar, a 2-DOF pendulum whose
    chaotic motion (and chart switches near type II singularities) grows a 1e-16 change
    of the drawing to ~1e-7 by 1 s."""
    t_end = 1.0 if len(model["coordinates"]) == 1 else 0.5
    res = pd.from_dict(model).simulate(t_end=t_end, t_eval=np.linspace(0.0, t_end, 11), method="dop853",
                                       rtol=RTOL, atol=ATOL)
    assert res.success, res.message
    return res.q


@settings(max_examples=12, deadline=None, suppress_health_check=list(HealthCheck))
@given(mechanisms)
def test_random_mechanism_closes_and_conserves_energy(model):
    mech = pd.from_dict(model)
    np.testing.assert_allclose(mech.assemble(mech.drawn_q), mech.x0, atol=1e-12 * mech.scale)
    res = mech.simulate(t_end=1.0, method="dop853", rtol=RTOL, atol=ATOL)
    assert res.success, res.message
    # The loop closes along the way: every link keeps its drawn length.
    names = mech.point_names
    pts = mech.point_positions(res.x)  # (N, P, 2)
    for body in model["bodies"].values():
        i, j = names.index(body["points"][0]), names.index(body["points"][1])
        drawn = math.dist(model["points"][body["points"][0]], model["points"][body["points"][1]])
        np.testing.assert_allclose(np.linalg.norm(pts[:, i] - pts[:, j], axis=1), drawn, rtol=1e-10)
    assert res.energy.drift / res.energy.kinetic.max() < ENERGY_REL


def transformed(model: dict, alpha: float, shift: tuple[float, float]) -> dict:
    """The same mechanism drawn in another frame: points and gravity turned by alpha and the
    points shifted; the (ground-attached, absolute-angle) coordinates grow by alpha."""
    m = copy.deepcopy(model)
    c, s = math.cos(alpha), math.sin(alpha)
    rot = lambda v: [c * v[0] - s * v[1], s * v[0] + c * v[1]]  # noqa: E731
    m["points"] = {k: [a + b for a, b in zip(rot(v), shift)] for k, v in m["points"].items()}
    m["gravity"] = rot(m["gravity"])
    for coord in m["coordinates"]:
        coord["value"] += alpha
    return m


@settings(max_examples=8, deadline=None, suppress_health_check=list(HealthCheck))
@given(mechanisms, st.floats(-math.pi, math.pi), st.tuples(st.floats(-5, 5), st.floats(-5, 5)))
def test_random_mechanism_does_not_depend_on_the_drawing_frame(model, alpha, shift):
    q = q_of(model)
    q2 = q_of(transformed(model, alpha, shift))
    np.testing.assert_allclose(q2 - alpha, q, atol=SAME_Q)


@settings(max_examples=8, deadline=None, suppress_health_check=list(HealthCheck))
@given(mechanisms, st.randoms(use_true_random=False))
def test_random_mechanism_does_not_depend_on_listing_order(model, rnd):
    m = copy.deepcopy(model)
    for key in ("points", "bodies"):
        items = list(m[key].items())
        rnd.shuffle(items)
        m[key] = dict(items)
    rnd.shuffle(m["pairs"])
    rnd.shuffle(m["ground"])
    np.testing.assert_allclose(q_of(m), q_of(model), atol=SAME_Q)
