"""The shipped model files: schema, names, mobility, drawings, and the benchmarks' numbers.

Pure data tests (no planardyn import): they check `examples/models/*.yaml` against
`schema/planardyn-model.schema.json`, resolve every name the way the loader does, check the
mobility 3n - 2p, and check that the three validation benchmarks are reproduced number for
number from `tests/data/benchmarks/*.json` (provenance: `tests/data/PROVENANCE.md`).
"""

from __future__ import annotations

import copy
import hashlib
import json
import math
import re
from pathlib import Path

import jsonschema
import pytest
import yaml

ROOT = Path(__file__).parents[1]
MODELS = ROOT / "examples" / "models"
SCHEMA_PATH = ROOT / "schema" / "planardyn-model.schema.json"
DOC_PATH = ROOT / "docs" / "model-format.md"
BENCHMARKS = ROOT / "tests" / "data" / "benchmarks"
PROVENANCE = ROOT / "tests" / "data" / "PROVENANCE.md"

BENCHMARK_STEMS = ["four-bar-gravity", "andrews-squeezer", "five-bar-free-fall"]
# file -> (mobile bodies n, pairs p, coordinates m), counted by hand from each drawing.
EXPECTED_COUNTS = {
    "four-bar-gravity.yaml": (3, 4, 1),
    "andrews-squeezer.yaml": (7, 10, 1),
    "five-bar-free-fall.yaml": (4, 5, 2),
    "five-bar.yaml": (4, 5, 2),
    "five-bar-compliant.yaml": (4, 5, 2),
    "five-bar-robot.yaml": (4, 5, 2),
    "slider-crank.yaml": (3, 4, 1),
    "hydraulic-boom.yaml": (3, 4, 1),
    "3-rrr.yaml": (7, 9, 3),
    "scotch-yoke.yaml": (2, 3, 1),
    "gear-train.yaml": (4, 7, 1),
    "geared-five-bar.yaml": (4, 6, 1),
}
# Constraint rows of each pair kind (docs/model-format.md): the mobility is 3n - their sum.
PAIR_ROWS = {"revolute": 2, "prismatic": 2, "slot": 1, "gear": 1}
# Geometry written by hand in the drawings is checked to this (m, rad): the numbers are
# pasted at full double precision, so only the last-digit rounding of the generator remains.
GEOMETRY_TOL = 1e-14
# A drawn coordinate value is a number pasted at full precision from math.radians of a whole
# degree: equal to it to the last bit or so (1 ulp of 2 rad is 4.4e-16).
PASTED_ANGLE_TOL = 1e-15


# --------------------------------------------------------------------------- loading


class _UniqueKeyLoader(yaml.SafeLoader):
    """A SafeLoader that rejects a key given twice, as the Rust loader does (PyYAML keeps the last)."""


def _construct_unique_mapping(loader, node, deep=False):
    keys = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in keys:
            raise yaml.constructor.ConstructorError(
                None, None, f"duplicate key {key!r}", key_node.start_mark
            )
        keys.add(key)
    return loader.construct_mapping(node, deep=deep)


_UniqueKeyLoader.add_constructor(
    yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_unique_mapping
)


def load_yaml(text: str):
    return yaml.load(text, Loader=_UniqueKeyLoader)


def model_files() -> list[Path]:
    return sorted(MODELS.glob("*.yaml"))


def load_model(name: str) -> dict:
    return load_yaml((MODELS / name).read_text())


def load_benchmark(stem: str) -> dict:
    path = BENCHMARKS / f"{stem}.json"
    return json.loads(path.read_text())


@pytest.fixture(scope="module")
def validator() -> jsonschema.Draft202012Validator:
    schema = json.loads(SCHEMA_PATH.read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


# --------------------------------------------------------------------------- the loader's rules


def canonical(model: dict) -> dict:
    """Resolve the aliases (points_at_t0, fixed_points, inertia_about_com, role, point_mass_at)."""
    m = copy.deepcopy(model)
    for alias, name in [("points_at_t0", "points"), ("fixed_points", "ground")]:
        if alias in m:
            m[name] = m.pop(alias)
    for body in m.get("bodies", {}).values():
        for item in [body, *body.get("parts", [])]:
            for alias, name in [("inertia_about_com", "inertia"), ("role", "about"),
                                ("point_mass_at", "point_mass")]:
                if alias in item:
                    item[name] = item.pop(alias)
    m.setdefault("ground", [])
    m.setdefault("drives", [])
    m.setdefault("loads", [])
    return m


def reference_errors(model: dict) -> list[str]:
    """Every name that does not resolve, as 'path: problem' (the loader's rules, docs/model-format.md)."""
    m = canonical(model)
    errors: list[str] = []
    points = m["points"]
    bodies = m["bodies"]
    carried = {"ground": set(m["ground"])}
    carried.update({name: set(b["points"]) for name, b in bodies.items()})

    def point(path, p):
        if p not in points:
            errors.append(f"{path}: unknown point {p!r}")

    def body(path, b, ground_ok=True):
        if b not in bodies and not (ground_ok and b == "ground"):
            errors.append(f"{path}: unknown body {b!r}")
            return False
        return True

    def carries(path, b, p):
        if b in carried and p not in carried[b]:
            errors.append(f"{path}: body {b!r} does not carry point {p!r}")

    if "ground" in bodies:
        errors.append("bodies.ground: 'ground' is the fixed body's name")
    for i, p in enumerate(m["ground"]):
        point(f"ground[{i}]", p)
    for name, b in bodies.items():
        for i, p in enumerate(b["points"]):
            point(f"bodies.{name}.points[{i}]", p)
        items = [(f"bodies.{name}", b)] + [
            (f"bodies.{name}.parts[{k}]", part) for k, part in enumerate(b.get("parts", []))
        ]
        for path, item in items:
            for i, p in enumerate(item.get("uniform_bar", [])):
                point(f"{path}.uniform_bar[{i}]", p)
            if "point_mass" in item:
                point(f"{path}.point_mass", item["point_mass"])
            if isinstance(item.get("com"), str):
                point(f"{path}.com", item["com"])

    pair_names: dict[str, dict] = {}
    for i, pr in enumerate(m["pairs"]):
        path = f"pairs[{i}]"
        if "name" in pr:
            if pr["name"] in pair_names:
                errors.append(f"{path}.name: duplicate pair name {pr['name']!r}")
            pair_names[pr["name"]] = pr
        if pr["type"] == "gear":
            # the gear centres are carried by their gears and by the carrier; a rack's
            # pitch-line points by the rack
            carrier = pr.get("carrier", "ground")
            body(f"{path}.carrier", carrier)
            for k, c in enumerate(pr["centers"]):
                point(f"{path}.centers[{k}]", c)
                carries(f"{path}.centers[{k}]", carrier, c)
                if body(f"{path}.bodies[{k}]", pr["bodies"][k]):
                    carries(f"{path}.centers[{k}]", pr["bodies"][k], c)
            for k, p in enumerate(pr.get("rack", [])):
                point(f"{path}.rack[{k}]", p)
                carries(f"{path}.rack[{k}]", pr["bodies"][1], p)
            continue
        point(f"{path}.at", pr["at"])
        for k, b in enumerate(pr["bodies"]):
            # a prismatic or slot pair's guide body (a, k = 0) need not carry `at`: the guide
            # passes through its drawn position
            if body(f"{path}.bodies[{k}]", b) and (k == 1 or pr["type"] == "revolute"):
                carries(f"{path}.at", b, pr["at"])
        for k, p in enumerate(pr.get("along", [])):
            point(f"{path}.along[{k}]", p)

    coord_names: dict[str, dict] = {}
    used_pairs: set[str] = set()
    for i, c in enumerate(m["coordinates"]):
        path = f"coordinates[{i}]"
        if c["name"] in coord_names:
            errors.append(f"{path}.name: duplicate coordinate name {c['name']!r}")
        coord_names[c["name"]] = c
        if c["pair"] not in pair_names:
            errors.append(f"{path}.pair: unknown pair {c['pair']!r}")
        elif c["pair"] in used_pairs:
            errors.append(f"{path}.pair: pair {c['pair']!r} already has a coordinate")
        used_pairs.add(c["pair"])

    driven: set[str] = set()
    for i, d in enumerate(m["drives"]):
        path = f"drives[{i}]"
        if d["coordinate"] not in coord_names:
            errors.append(f"{path}.coordinate: unknown coordinate {d['coordinate']!r}")
        if d["coordinate"] in driven:
            errors.append(f"{path}.coordinate: coordinate {d['coordinate']!r} has two drives")
        driven.add(d["coordinate"])
        if "table" in d:
            t, e = d["table"]["t"], d["table"]["effort"]
            if len(t) != len(e):
                errors.append(f"{path}.table: t and effort differ in length")
            if any(b <= a for a, b in zip(t, t[1:])):
                errors.append(f"{path}.table.t: times must increase")

    for i, ld in enumerate(m["loads"]):
        path = f"loads[{i}]"
        kind = ld["type"]
        if kind in ("force", "torque"):
            body(f"{path}.body", ld["body"], ground_ok=False)
        if kind == "force":
            point(f"{path}.at", ld["at"])
            carries(f"{path}.at", ld["body"], ld["at"])
        if kind == "spring":
            for k, (b, p) in enumerate(ld["between"]):
                point(f"{path}.between[{k}][1]", p)
                if body(f"{path}.between[{k}][0]", b):
                    carries(f"{path}.between[{k}][1]", b, p)
        if kind in ("torsional_spring", "friction") and ld["pair"] not in pair_names:
            errors.append(f"{path}.pair: unknown pair {ld['pair']!r}")
    return errors


def mobility(model: dict) -> int:
    """3n - 2p - p1: every revolute and prismatic pair removes two degrees of freedom, every
    gear and slot pair one."""
    return 3 * len(model["bodies"]) - sum(PAIR_ROWS[pr["type"]] for pr in model["pairs"])


# --------------------------------------------------------------------------- inertia and energy


def _mass_properties(item: dict, points: dict) -> tuple[float, tuple[float, float], float]:
    """(mass kg, centre of mass m, inertia about it kg m^2) of a body or part (canonical names)."""
    if "parts" in item:
        parts = [_mass_properties(p, points) for p in item["parts"]]
        mass = sum(p[0] for p in parts)
        cx = sum(p[0] * p[1][0] for p in parts) / mass
        cy = sum(p[0] * p[1][1] for p in parts) / mass
        inertia = sum(i + mp * ((c[0] - cx) ** 2 + (c[1] - cy) ** 2) for mp, c, i in parts)
        return mass, (cx, cy), inertia
    mass = item["mass"]
    if "uniform_bar" in item:
        p, q = (points[n] for n in item["uniform_bar"])
        length = math.dist(p, q)
        return mass, ((p[0] + q[0]) / 2, (p[1] + q[1]) / 2), mass * length**2 / 12
    if "point_mass" in item:
        return mass, tuple(points[item["point_mass"]]), 0.0
    com = item["com"]
    com = tuple(points[com]) if isinstance(com, str) else tuple(com)
    return mass, com, item["inertia"]


def mass_properties(model: dict) -> dict[str, tuple[float, tuple[float, float], float]]:
    m = canonical(model)
    return {name: _mass_properties(b, m["points"]) for name, b in m["bodies"].items()}


def drawn_potential_energy(model: dict) -> float:
    """Gravity (-g . r of each centre of mass) plus linear springs, in the drawing (J)."""
    m = canonical(model)
    g = m.get("gravity", [0.0, 0.0])
    energy = 0.0
    for mass, com, _ in mass_properties(model).values():
        energy -= mass * (g[0] * com[0] + g[1] * com[1])
    for ld in m["loads"]:
        if ld["type"] == "spring" and "rest_length" in ld:
            (_, p), (_, q) = ld["between"]
            stretch = math.dist(m["points"][p], m["points"][q]) - ld["rest_length"]
            energy += 0.5 * ld["stiffness"] * stretch**2
    return energy


def drawn_angle(model: dict, body: str) -> float:
    """A body's angle in the drawing: the line from its first to its second point."""
    m = canonical(model)
    pts = m["bodies"][body]["points"]
    if len(pts) < 2:
        return 0.0
    (x0, y0), (x1, y1) = m["points"][pts[0]], m["points"][pts[1]]
    return math.atan2(y1 - y0, x1 - x0)


# --------------------------------------------------------------------------- every file


def test_the_shipped_models_are_the_expected_ones():
    assert sorted(p.name for p in model_files()) == sorted(EXPECTED_COUNTS)


def test_schema_is_valid_draft_2020_12():
    schema = json.loads(SCHEMA_PATH.read_text())
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    jsonschema.Draft202012Validator.check_schema(schema)


@pytest.mark.parametrize("path", model_files(), ids=lambda p: p.name)
def test_model_file_validates_against_schema(path, validator):
    model = load_yaml(path.read_text())
    errors = [f"{'/'.join(map(str, e.absolute_path))}: {e.message}" for e in validator.iter_errors(model)]
    assert errors == []


@pytest.mark.parametrize("path", model_files(), ids=lambda p: p.name)
def test_every_name_resolves(path):
    assert reference_errors(load_yaml(path.read_text())) == []


@pytest.mark.parametrize("path", model_files(), ids=lambda p: p.name)
def test_mobility_equals_number_of_coordinates(path):
    model = load_yaml(path.read_text())
    n, p, m = EXPECTED_COUNTS[path.name]
    assert (len(model["bodies"]), len(model["pairs"]), len(model["coordinates"])) == (n, p, m)
    assert mobility(model) == m


@pytest.mark.parametrize("path", model_files(), ids=lambda p: p.name)
def test_every_body_has_positive_mass_and_inertia(path):
    for name, (mass, _, inertia) in mass_properties(load_yaml(path.read_text())).items():
        assert mass > 0, name
        assert inertia > 0, name


@pytest.mark.parametrize("path", model_files(), ids=lambda p: p.name)
def test_body_angles_are_defined(path):
    """A body's first two points must be distinct in the drawing (its angle is their line's)."""
    model = canonical(load_yaml(path.read_text()))
    for name, body in model["bodies"].items():
        if len(body["points"]) >= 2:
            p, q = (model["points"][n] for n in body["points"][:2])
            assert math.dist(p, q) > 0, name


# --------------------------------------------------------------------------- the checker itself


def test_reference_checker_reports_each_broken_name():
    good = load_model("andrews-squeezer.yaml")
    assert reference_errors(good) == []
    bad = copy.deepcopy(good)
    bad["pairs"][2]["at"] = "G"  # b2 and b3 do not carry G
    bad["coordinates"][0]["pair"] = "no_such_pair"
    bad["drives"][0]["coordinate"] = "alpha"
    bad["loads"][0]["between"][0] = ["b3", "C"]
    bad["bodies"]["b4"]["points"].append("Z")
    assert reference_errors(bad) == [
        "bodies.b4.points[2]: unknown point 'Z'",
        "pairs[2].at: body 'b2' does not carry point 'G'",
        "pairs[2].at: body 'b3' does not carry point 'G'",
        "coordinates[0].pair: unknown pair 'no_such_pair'",
        "drives[0].coordinate: unknown coordinate 'alpha'",
        "loads[0].between[0][1]: body 'b3' does not carry point 'C'",
    ]


def test_duplicate_yaml_keys_are_rejected():
    with pytest.raises(yaml.constructor.ConstructorError, match="duplicate key 'b1'"):
        load_yaml("bodies:\n  b1: {points: [O]}\n  b1: {points: [P]}\n")


# --------------------------------------------------------------------------- the schema's rules


def _four_bar() -> dict:
    return load_model("four-bar-gravity.yaml")


def test_schema_accepts_the_aliases(validator):
    model = _four_bar()
    model["points_at_t0"] = model.pop("points")
    model["fixed_points"] = model.pop("ground")
    crank = model["bodies"]["crank"]
    crank["inertia_about_com"] = crank.pop("inertia")
    crank["role"] = "crank"
    model["bodies"]["coupler"] = {
        "points": ["A", "B"],
        "parts": [{"uniform_bar": ["A", "B"], "mass": 1.0}, {"point_mass_at": "B", "mass": 0.2}],
    }
    assert list(validator.iter_errors(model)) == []
    assert reference_errors(model) == []


def _mutations():
    def unknown_top(m): m["colour"] = "red"
    def unknown_body_field(m): m["bodies"]["crank"]["density"] = 1.0
    def alias_and_name(m): m["points_at_t0"] = m["points"]
    def ground_and_alias(m): m["fixed_points"] = m["ground"]
    def inertia_twice(m): m["bodies"]["crank"]["inertia_about_com"] = 0.01
    def zero_mass(m): m["bodies"]["crank"]["mass"] = 0.0
    def negative_inertia(m): m["bodies"]["crank"]["inertia"] = -1.0
    def no_com(m): del m["bodies"]["crank"]["com"]
    def bar_and_com(m): m["bodies"]["crank"]["uniform_bar"] = ["O", "A"]
    def point_mass_alone(m): m["bodies"]["crank"] = {"points": ["O", "A"], "point_mass": "A", "mass": 1.0}
    def body_named_ground(m): m["bodies"]["ground"] = m["bodies"].pop("crank")
    def units_mm(m): m["units"] = "mm"
    def point_named_ground(m): m["points"]["ground"] = [0.0, 0.0]
    def force_on_ground(m): m["loads"] = [{"type": "force", "body": "ground", "at": "O", "value": [1.0, 0.0]}]
    def gravity_3d(m): m["gravity"] = [0.0, -9.81, 0.0]
    def point_1d(m): m["points"]["O"] = [0.0]
    def revolute_with_axis(m): m["pairs"][0]["axis"] = [1.0, 0.0]
    def pair_type_unknown(m): m["pairs"][0]["type"] = "spherical"
    def pair_same_body(m): m["pairs"][0]["bodies"] = ["crank", "crank"]
    def prismatic_no_direction(m): m["pairs"][0] = {"type": "prismatic", "at": "O", "bodies": ["ground", "crank"]}
    def prismatic_both(m): m["pairs"][0] = {"type": "prismatic", "at": "O", "bodies": ["ground", "crank"], "axis": [1.0, 0.0], "along": ["O", "D"]}
    def prismatic_zero_axis(m): m["pairs"][0] = {"type": "prismatic", "at": "O", "bodies": ["ground", "crank"], "axis": [0.0, 0.0]}
    def coordinate_no_value(m): del m["coordinates"][0]["value"]
    def no_coordinates(m): m["coordinates"] = []
    def drive_both(m): m["drives"] = [{"coordinate": "theta1", "effort": 1.0, "table": {"t": [0.0], "effort": [1.0]}}]
    def drive_neither(m): m["drives"] = [{"coordinate": "theta1"}]
    def load_type_unknown(m): m["loads"] = [{"type": "magnet", "pair": "ground_crank"}]
    def spring_extra_field(m): m["loads"] = [{"type": "spring", "between": [["ground", "O"], ["crank", "A"]], "stiffness": 1.0, "pair": "x"}]
    def friction_no_viscous(m): m["loads"] = [{"type": "friction", "pair": "ground_crank"}]
    def torque_vector(m): m["loads"] = [{"type": "torque", "body": "crank", "value": [1.0, 0.0]}]
    def method_unknown(m): m["simulate"]["method"] = "euler"
    def t_end_zero(m): m["simulate"]["t_end"] = 0.0
    def number_as_string(m): m["bodies"]["crank"]["mass"] = "0.5"
    return [f for f in locals().values() if callable(f)]


@pytest.mark.parametrize("mutate", _mutations(), ids=lambda f: f.__name__)
def test_schema_rejects(mutate, validator):
    model = _four_bar()
    assert list(validator.iter_errors(model)) == []
    mutate(model)
    assert list(validator.iter_errors(model)) != []


def test_schema_accepts_every_pair_and_load_kind(validator):
    model = _four_bar()
    model["pairs"].append({"type": "prismatic", "name": "s1", "at": "B", "bodies": ["coupler", "rocker"], "axis": [1.0, 2.0]})
    model["pairs"].append({"type": "prismatic", "at": "B", "bodies": ["ground", "rocker"], "along": ["O", "D"]})
    model["coordinates"][0].update(q0=1.2, qd0=-0.5, about="text")
    model["drives"] = [{"coordinate": "theta1", "table": {"t": [0.0, 1.0], "effort": [0.0, 2.0]}}]
    model["loads"] = [
        {"type": "force", "body": "crank", "at": "A", "value": [1.0, -2.0]},
        {"type": "torque", "body": "rocker", "value": -0.5},
        {"type": "spring", "between": [["ground", "D"], ["crank", "A"]], "stiffness": 10.0},
        {"type": "spring", "between": [["coupler", "B"], ["crank", "O"]], "stiffness": 1.0, "damping": 0.1, "rest_length": 0.4},
        {"type": "torsional_spring", "pair": "ground_crank", "stiffness": 2.0, "damping": 0.01, "rest": 0.3},
        {"type": "friction", "pair": "s1", "viscous": 0.5},
    ]
    model["simulate"] = {"t_end": 1.0, "method": "rk4", "rtol": 1e-6, "atol": 1e-9, "dt": 1e-3, "output_dt": 0.01}
    assert list(validator.iter_errors(model)) == []


# --------------------------------------------------------------------------- the benchmarks, number for number


@pytest.mark.parametrize("stem", BENCHMARK_STEMS)
def test_benchmark_copy_is_the_one_provenance_names(stem):
    """The copy in tests/data/benchmarks is byte for byte the file whose sha256 PROVENANCE.md records."""
    digest = hashlib.sha256((BENCHMARKS / f"{stem}.json").read_bytes()).hexdigest()
    assert f"| `{stem}.json` | `{digest}` |" in PROVENANCE.read_text()


@pytest.mark.parametrize("stem", BENCHMARK_STEMS)
def test_benchmark_reproduced_exactly(stem):
    src = load_benchmark(stem)
    model = canonical(load_model(f"{stem}.yaml"))

    assert model["name"] == src["name"]
    assert src["about"] in model["about"]
    assert src["checks_without_reference"] in model["about"]
    assert model["gravity"] == src["gravity"]
    assert model["units"] == "SI"

    # points: same names, same order, identical numbers
    assert list(model["points"]) == list(src["points_at_t0"])
    for name, xy in src["points_at_t0"].items():
        assert model["points"][name] == xy, name
    assert model["ground"] == src["fixed_points"]

    # bodies: same names and order, points, and every inertia number
    assert list(model["bodies"]) == list(src["bodies"])
    for name, sb in src["bodies"].items():
        mb = model["bodies"][name]
        assert mb["points"] == sb["points"], name
        assert mb.get("about") == sb.get("role"), name
        if "parts" in sb:
            assert len(mb["parts"]) == len(sb["parts"])
            for mp, sp in zip(mb["parts"], sb["parts"]):
                assert mp["mass"] == sp["mass"]
                assert mp.get("uniform_bar") == sp.get("uniform_bar")
                assert mp.get("point_mass") == sp.get("point_mass_at")
        else:
            assert mb["mass"] == sb["mass"], name
            assert mb["inertia"] == sb["inertia_about_com"], name
            assert mb["com"] == sb["com"], name

    # pairs: all revolute, same order, points and bodies (a = first, b = second)
    assert [p["type"] for p in model["pairs"]] == ["revolute"] * len(src["revolute_pairs"])
    assert [(p["at"], p["bodies"]) for p in model["pairs"]] == [
        (p["at"], p["bodies"]) for p in src["revolute_pairs"]
    ]

    # coordinates: the absolute crank angles, value = the source's initial value
    src_coords = src.get("generalized_coordinates") or [src["generalized_coordinate"]]
    assert [c["name"] for c in model["coordinates"]] == [c["name"] for c in src_coords]
    pairs = {p["name"]: p for p in model["pairs"]}
    for mc, sc in zip(model["coordinates"], src_coords):
        assert mc["value"] == sc["initial_value"], mc["name"]
        assert mc.get("qd0", 0.0) == sc.get("initial_rate", 0.0), mc["name"]
        assert "q0" not in mc
        a, b = pairs[mc["pair"]]["bodies"]
        assert a == "ground"
        # the crank's drawn angle (its first->second line) is the source's initial value
        assert drawn_angle(model, b) == pytest.approx(sc["initial_value"], abs=GEOMETRY_TOL)

    # drives
    drives = {d["coordinate"]: d["effort"] for d in model["drives"]}
    drv = src["drive"]
    if drv is None:
        assert drives == {}
    elif "on" in drv:
        assert drives == {drv["on"]: drv["torque"]}
    else:
        assert drives == drv

    # the spring
    springs = [ld for ld in model["loads"] if ld["type"] == "spring"]
    if "spring" in src:
        s = src["spring"]
        assert springs == [{
            "type": "spring",
            "between": s["between"],
            "stiffness": s["stiffness"],
            "damping": s["damping"],
            "rest_length": s["rest_length"],
        }]
        assert len(model["loads"]) == 1
    else:
        assert model["loads"] == []

    assert model["simulate"] == src["simulate"]


def test_andrews_specifics():
    """The two numbers the source names: drive 0.033 N m on beta, spring [b3, D] - [ground, C]."""
    model = load_model("andrews-squeezer.yaml")
    assert model["drives"] == [{"coordinate": "beta", "effort": 0.033}]
    spring = model["loads"][0]
    assert spring["between"] == [["b3", "D"], ["ground", "C"]]
    assert (spring["stiffness"], spring["rest_length"]) == (4530.0, 0.07785)


def test_five_bar_free_fall_distal_left_parts():
    model = canonical(load_model("five-bar-free-fall.yaml"))
    assert model["bodies"]["distal_left"]["parts"] == [
        {"uniform_bar": ["C1", "P"], "mass": 0.25},
        {"point_mass": "P", "mass": 0.1},
    ]
    mass, com, inertia = mass_properties(model)["distal_left"]
    # bar 0.25 kg, |C1 P| = 0.25 m: I = 0.25 * 0.25^2 / 12 about its midpoint; plus parallel axis
    c1, p = model["points"]["C1"], model["points"]["P"]
    mid = ((c1[0] + p[0]) / 2, (c1[1] + p[1]) / 2)
    d_bar = math.dist(mid, com)
    d_pm = math.dist(p, com)
    assert mass == pytest.approx(0.35, rel=1e-15)
    assert math.dist(c1, p) == pytest.approx(0.25, abs=GEOMETRY_TOL)
    assert inertia == pytest.approx(0.25 * 0.25**2 / 12 + 0.25 * d_bar**2 + 0.1 * d_pm**2, rel=1e-14)


# Energies of the drawings quoted by the sources (PROVENANCE.md), checked to half a unit in the
# last decimal they quote: that is all the figure carries.
DRAWN_ENERGY = {
    # "Total energy (kinetic + m g y of each centre of mass) stays at 13.770736975732 J"
    "four-bar-gravity": "13.770736975732",
    # "Total energy stays at 1.874338473780 J"
    "five-bar-free-fall": "1.874338473780",
    # "T + V_spring - mom*(beta - beta0) stays equal to its value at t = 0 (about 1.43580 J)"
    "andrews-squeezer": "1.43580",
}


@pytest.mark.parametrize("stem", BENCHMARK_STEMS)
def test_drawn_energy_matches_checks_without_reference(stem):
    """At rest in the drawing the total energy is the potential one: the model file's masses,
    centres of mass (uniform bars, point masses) and spring give the source's figure."""
    figure = DRAWN_ENERGY[stem]
    assert figure in load_benchmark(stem)["checks_without_reference"]
    half_unit = 0.5 * 10.0 ** -len(figure.split(".")[1])
    model = load_model(f"{stem}.yaml")
    assert all(c.get("qd0", 0.0) == 0.0 for c in model["coordinates"])
    assert drawn_potential_energy(model) == pytest.approx(float(figure), rel=0, abs=half_unit)


def test_benchmark_inertias_are_uniform_bars_where_the_source_says_so():
    """four-bar and five-bar sources: every link a uniform slender bar of 1 kg per metre."""
    for stem in ["four-bar-gravity", "five-bar-free-fall"]:
        model = canonical(load_model(f"{stem}.yaml"))
        for name, body in model["bodies"].items():
            if "parts" in body:
                continue
            p, q = (model["points"][n] for n in body["points"][:2])
            length = math.dist(p, q)
            assert body["mass"] == pytest.approx(1.0 * length, rel=1e-12), name
            assert body["inertia"] == pytest.approx(body["mass"] * length**2 / 12, rel=1e-12), name
            assert body["com"] == pytest.approx([(p[0] + q[0]) / 2, (p[1] + q[1]) / 2], abs=GEOMETRY_TOL), name


# --------------------------------------------------------------------------- the hand-made drawings


def _pt(model, name):
    return model["points"][name]


def test_five_bar_drawing():
    model = load_model("five-bar.yaml")
    a1, a2, c1, c2, p = (_pt(model, n) for n in ["A1", "A2", "C1", "C2", "P"])
    assert math.dist(a1, c1) == pytest.approx(0.25, abs=GEOMETRY_TOL)
    assert math.dist(a2, c2) == pytest.approx(0.25, abs=GEOMETRY_TOL)
    assert math.dist(c1, p) == pytest.approx(0.35, abs=GEOMETRY_TOL)
    assert math.dist(c2, p) == pytest.approx(0.35, abs=GEOMETRY_TOL)
    theta = {c["name"]: c["value"] for c in model["coordinates"]}
    assert theta == {"theta1": pytest.approx(math.radians(115.0), abs=PASTED_ANGLE_TOL),
                     "theta2": pytest.approx(math.radians(60.0), abs=PASTED_ANGLE_TOL)}
    assert drawn_angle(model, "proximal_left") == pytest.approx(theta["theta1"], abs=GEOMETRY_TOL)
    assert drawn_angle(model, "proximal_right") == pytest.approx(theta["theta2"], abs=GEOMETRY_TOL)

    # away from singularities: no two of (proximal, distal) collinear, distal links not collinear
    def sin_between(u0, u1, v0, v1):
        u = (u1[0] - u0[0], u1[1] - u0[1])
        v = (v1[0] - v0[0], v1[1] - v0[1])
        return abs(u[0] * v[1] - u[1] * v[0]) / (math.hypot(*u) * math.hypot(*v))

    assert sin_between(a1, c1, c1, p) > 0.9
    assert sin_between(a2, c2, c2, p) > 0.9
    assert sin_between(c1, p, c2, p) > 0.9
    assert p[1] > max(c1[1], c2[1])  # upper working mode
    # the drives: a constant and a table
    drives = {d["coordinate"]: d for d in model["drives"]}
    assert drives["theta1"]["effort"] == -2.41
    assert drives["theta2"]["table"] == {"t": [0.0, 0.2, 0.6, 0.8], "effort": [2.61, 3.2, 3.2, 2.61]}


def test_slider_crank_drawing():
    model = load_model("slider-crank.yaml")
    o, a, b = (_pt(model, n) for n in ["O", "A", "B"])
    assert math.dist(o, a) == pytest.approx(0.08, abs=GEOMETRY_TOL)
    assert math.dist(a, b) == pytest.approx(0.3, abs=GEOMETRY_TOL)
    assert b[1] == 0.0  # on the guide, the x axis through O
    guide = next(p for p in model["pairs"] if p["type"] == "prismatic")
    assert guide["bodies"] == ["ground", "slider"] and guide["axis"] == [1.0, 0.0] and guide["at"] == "B"
    (coord,) = model["coordinates"]
    assert coord["pair"] == "crank_pivot"
    assert coord["value"] == pytest.approx(math.radians(60.0), abs=PASTED_ANGLE_TOL)
    assert drawn_angle(model, "crank") == pytest.approx(coord["value"], abs=GEOMETRY_TOL)
    assert drawn_angle(model, "slider") == 0.0  # one point
    assert {ld["type"] for ld in model["loads"]} == {"spring", "friction"}


def test_hydraulic_boom_drawing():
    model = load_model("hydraulic-boom.yaml")
    o, t, r, g, e, k = (_pt(model, n) for n in ["O", "T", "R", "G", "E", "K"])
    assert math.dist(o, t) == pytest.approx(3.0, abs=GEOMETRY_TOL)
    assert math.dist(o, r) == pytest.approx(1.5, abs=GEOMETRY_TOL)
    # R on the boom line O-T, E and K on the cylinder line G-R
    def cross(p, q, s):
        return (q[0] - p[0]) * (s[1] - p[1]) - (q[1] - p[1]) * (s[0] - p[0])
    assert cross(o, t, r) == pytest.approx(0.0, abs=GEOMETRY_TOL)
    assert cross(g, r, e) == pytest.approx(0.0, abs=GEOMETRY_TOL)
    assert cross(g, r, k) == pytest.approx(0.0, abs=GEOMETRY_TOL)
    assert math.dist(g, e) == pytest.approx(0.9, abs=GEOMETRY_TOL)
    assert math.dist(g, k) == pytest.approx(0.45, abs=GEOMETRY_TOL)
    # the input: a relative prismatic pair between two mobile bodies, q = pin-to-pin length
    cyl = next(p for p in model["pairs"] if p["type"] == "prismatic")
    assert cyl["bodies"] == ["barrel", "rod"] and cyl["at"] == "K" and cyl["along"] == ["G", "E"]
    assert all(b != "ground" for b in cyl["bodies"])
    (coord,) = model["coordinates"]
    assert coord["pair"] == cyl["name"]
    assert coord["value"] == pytest.approx(math.dist(g, r), abs=GEOMETRY_TOL)
    assert model["drives"][0]["coordinate"] == "extension"
    assert "table" in model["drives"][0]


# --------------------------------------------------------------------------- the reference page


def _doc_blocks(lang: str) -> list[str]:
    text = DOC_PATH.read_text()
    return re.findall(r"<!-- complete-example -->\s*```" + lang + r"\n(.*?)```", text, re.S)


def test_doc_example_yaml_and_json_are_the_same_valid_model(validator):
    (yaml_text,) = _doc_blocks("yaml")
    (json_text,) = _doc_blocks("json")
    from_yaml = load_yaml(yaml_text)
    from_json = json.loads(json_text)
    assert from_yaml == from_json
    assert list(validator.iter_errors(from_yaml)) == []
    assert reference_errors(from_yaml) == []
    assert mobility(from_yaml) == len(from_yaml["coordinates"]) == 1
    # it is the four-bar benchmark's mechanism
    shipped = canonical(load_model("four-bar-gravity.yaml"))
    doc = canonical(from_yaml)
    for key in ["points", "ground", "bodies", "pairs", "coordinates", "gravity"]:
        assert doc[key] == shipped[key], key
