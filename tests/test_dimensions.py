"""Mechanisms written by their dimensions (issue 26 item 1): the Hoeken linkage, a quick-return
shaper and a 3-RPR robot, each as a model file by its dimensions and with
:class:`planardyn.Builder`, give the mechanisms of their coordinate versions; the Hoeken
coupler point's straight line; units; the check's report; SVG and DXF drawings read back.

The Hoeken file and the three builders are docs/dimensions.md's own (its Python blocks run
here, in a folder of their own, as the reader runs them); the shaper's and the 3-RPR's files
and the coordinate versions are in tests/data/dimensions/."""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import xml.etree.ElementTree as ET

import jsonschema
import numpy as np
import planardyn as pdy
import pytest
from conftest import ROOT
from planardyn import cli, library
from planardyn.drawing import MM_PER_M, write_drawing
from wheel_smoke import snippets

DATA = ROOT / "tests" / "data" / "dimensions"
PAGE = ROOT / "docs" / "dimensions.md"
SCHEMA = json.loads((ROOT / "schema" / "planardyn-model.schema.json").read_text())

#: Round-off of the constructions (a few products, square roots and atan2 of numbers near
#: 0.1-1 m): two drawings of one mechanism agree to a few ulps of 1 m; at other inputs the
#: assembly's Newton iterations, converged to the loader's tolerance, add the same order.
SAME_DRAWING = 1e-12


def points(mech: pdy.Mechanism, x: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Every point (m) at body coordinates x (default: the drawing), by name."""
    return dict(zip(mech.point_names, mech.point_positions(mech.x0 if x is None else x)))


def assert_same_mechanism(a: pdy.Mechanism, b: pdy.Mechanism, inputs: list[np.ndarray], guides: tuple = ()) -> None:
    """The same points where drawn and at each input q, the same masses and inertias (``a``
    may have the ground points ``guides`` more, drawn only to construct others)."""
    assert sorted(a.point_names) == sorted([*b.point_names, *guides])
    for qa in [None, *inputs]:
        xa = None if qa is None else a.assemble(qa)
        xb = None if qa is None else b.assemble(qa)
        pa, pb = points(a, xa), points(b, xb)
        gap = max(float(np.max(np.abs(pa[n] - pb[n]))) for n in pb)
        assert gap < SAME_DRAWING, f"at q = {qa}: points differ by {gap:.3e} m"
    np.testing.assert_allclose(a.drawn_q, b.drawn_q, rtol=0, atol=SAME_DRAWING)
    # The same masses and inertias computed from the two descriptions' numbers: a few ulps
    # (masses measured identical over the file's cases, inertias, sums of products taken in
    # another order, 3.3e-16 relative; 2026-11-25, s8-revpy notes).
    np.testing.assert_allclose(a.masses, b.masses, rtol=1e-15)
    np.testing.assert_allclose(a.inertias, b.inertias, rtol=1e-13)


@pytest.fixture(scope="module")
def page(tmp_path_factory) -> dict:
    """The namespace of docs/dimensions.md's Python blocks, run in order in an empty folder
    (which then holds the files they wrote: hoeken.yaml, shaper.yaml...)."""
    folder = tmp_path_factory.mktemp("dimensions")
    namespace: dict = {"__name__": "dimensions_page"}
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        for kind, code in snippets(PAGE.read_text()):
            if kind == "python":
                with contextlib.redirect_stdout(io.StringIO()):
                    exec(compile(code, str(PAGE), "exec"), namespace)
    finally:
        os.chdir(cwd)
    namespace["folder"] = folder
    return namespace


# ----------------------------------------------------------------------------- Hoeken


HOEKEN_INPUTS = [np.array([t]) for t in (math.pi / 2, 2.5, 4.0, 3 * math.pi / 2)]


def test_hoeken_by_dimensions_is_hoeken_by_coordinates(page):
    coords = pdy.load(DATA / "hoeken-coordinates.yaml")
    assert_same_mechanism(pdy.load(page["folder"] / "hoeken.yaml"), coords, HOEKEN_INPUTS)
    assert_same_mechanism(page["built"], coords, HOEKEN_INPUTS)
    assert_same_mechanism(pdy.load(page["folder"] / "hoeken-built.yaml"), coords, HOEKEN_INPUTS)


def test_hoeken_coupler_point_runs_on_its_straight_line(page):
    # Analytic: at theta = 90, 180, 270 deg the coupler and rocker circles meet at B with
    # 3-4-5 triangles, and P = A + 2 (B - A) is (200, 200), (100, 200), (0, 200) mm exactly.
    mech = pdy.load(page["folder"] / "hoeken.yaml")
    for theta, expected in ((math.pi / 2, (0.2, 0.2)), (math.pi, (0.1, 0.2)), (3 * math.pi / 2, (0.0, 0.2))):
        p = points(mech, mech.assemble([theta]))["P"]
        np.testing.assert_allclose(p, expected, rtol=0, atol=SAME_DRAWING)


# ----------------------------------------------------------------------------- shaper


def shaper_coordinates() -> pdy.Mechanism:
    """docs/first-hour.md's shaper by coordinates (its formulas), with the guide's ends G, H."""
    r, lever, link, ram_y = 0.1, 0.5, 0.15, 0.5
    A = (r, 0.2)
    k = lever / math.hypot(*A)
    B = (k * A[0], k * A[1])
    C = (B[0] + math.sqrt(link**2 - (ram_y - B[1]) ** 2), ram_y)
    model = pdy.load(DATA / "shaper.yaml").to_dict()
    model["points"] = {"O1": [0.0, 0.0], "O2": [0.0, 0.2], "A": list(A), "B": list(B), "G": [0.0, 0.5],
                       "H": [1.0, 0.5], "C": list(C), "T": [C[0] + 0.25, ram_y]}
    model["pairs"][-1] = {"type": "prismatic", "name": "ram_guide", "at": "C", "bodies": ["ground", "ram"],
                          "axis": [1.0, 0.0]}
    model["coordinates"][0]["value"] = 0.0
    return pdy.from_dict(model)


SHAPER_INPUTS = [np.array([t]) for t in (0.5, 1.5, 3.0, 5.0)]


def test_shaper_by_dimensions_is_the_shaper_by_coordinates(page):
    coords = shaper_coordinates()
    assert_same_mechanism(pdy.load(DATA / "shaper.yaml"), coords, SHAPER_INPUTS)
    assert_same_mechanism(page["shaper"], coords, SHAPER_INPUTS)


# ----------------------------------------------------------------------------- 3-RPR


def test_three_rpr_by_dimensions_is_the_librarys(page):
    coords = library.three_rpr()
    inputs = [coords.drawn_q + d for d in (np.array([0.02, -0.01, 0.0]), np.array([-0.03, 0.02, 0.01]))]
    assert_same_mechanism(pdy.load(DATA / "3-rpr.yaml"), coords, inputs)
    assert_same_mechanism(page["robot"], coords, inputs)


# ----------------------------------------------------------------------------- gears


def test_a_gear_train_by_its_dimensions_is_the_shipped_one():
    # The centres from the pitch radii: O2 at 20 + 60 mm from O1 (external), O3 at 45 - 25 mm
    # from O2 (inside the ring); a mark on each gear at its pitch radius, straight up.
    b = pdy.Builder("gear train", gravity=(0, 0))
    b.point("O1", (0, 0), ground=True)
    b.polar("T1", "O1", "20 mm", "90 deg")
    b.polar("O2", "O1", "80 mm", 0, ground=True)
    b.polar("T2", "O2", "60 mm", "90 deg")
    b.polar("O3", "O2", "20 mm", 0, ground=True)
    b.polar("T3", "O3", "45 mm", "90 deg")
    b.point("R1", ("-100 mm", "-20 mm"))
    b.point("R2", ("100 mm", "-20 mm"))
    for gear, centre, mark, mass, inertia in (("pinion", "O1", "T1", "200 g", 4.0e-5), ("wheel", "O2", "T2", "600 g", 0.00108),
                                              ("ring", "O3", "T3", "400 g", 0.00081)):
        b.block(gear, centre, mass, inertia)
        b.carry(gear, mark)
        b.revolute(f"{gear}_shaft", centre, "ground", gear)
    b.bar("rack", ["R1", "R2"], mass="300 g")
    b.prismatic("rack_guide", "R1", "ground", "rack", axis=(1, 0))
    b.gear("mesh1", "pinion", "wheel", ["O1", "O2"], ["20 mm", "60 mm"])
    b.gear("mesh2", "wheel", "ring", ["O2", "O3"], ["25 mm", "45 mm"], internal=True)
    b.gear("rack_mesh", "pinion", "rack", ["O1"], ["20 mm"], rack=("R1", "R2"))
    b.coordinate("theta", "pinion_shaft", 0)
    assert_same_mechanism(b.build(), pdy.load_example("gear-train"), [np.array([0.3]), np.array([-1.0])])


# ----------------------------------------------------------------------------- slider-crank


def test_a_slider_crank_by_its_dimensions_is_the_librarys():
    # library.slider_crank at its defaults: crank 0.1 m at 60 deg, rod 0.3 m, the slider on y = 0
    # ahead of the crank pin; the guide's line by its ends G, H (ground points of this drawing only).
    b = pdy.Builder("slider-crank")
    b.point("O", (0, 0))
    b.point("G", (0, 0), ground=True)
    b.point("H", ("1 m", 0), ground=True)
    b.crank("crank", "O", "A", "100 mm", "60 deg", rho=1.0, coordinate="theta")
    b.line_circle("B", ("G", "H"), "A", "300 mm", "second")
    b.bar("rod", ["A", "B"], rho=1.0)
    b.revolute("crank_pin", "A", "crank", "rod")
    b.slider("slider", "B", 0.5, 1.0e-3, axis=(1, 0))
    b.revolute("wrist_pin", "B", "rod", "slider")
    built = b.build()
    assert built.pair_names == ["ground_crank", "crank_pin", "ground_slider", "wrist_pin"]
    assert_same_mechanism(built, library.slider_crank(), [np.array([1.0]), np.array([3.0])], guides=("G", "H"))


# ----------------------------------------------------------------------------- files, units, errors


@pytest.mark.parametrize("path", [DATA / "shaper.yaml", DATA / "3-rpr.yaml", "hoeken.yaml", "hoeken-built.yaml",
                                  "shaper.yaml"])
def test_files_by_dimensions_validate_against_the_schema(path, page):
    import yaml

    jsonschema.Draft202012Validator(SCHEMA).validate(yaml.safe_load((page["folder"] / path).read_text()))


def test_the_builder_writes_json_too(page, tmp_path):
    page["b"].write(tmp_path / "robot.json")
    assert_same_mechanism(pdy.load(tmp_path / "robot.json"), page["robot"], [])


def test_units_convert_by_their_definitions():
    # The inch is 25.4 mm exactly, the degree pi/180 rad.
    model = pdy.load(DATA / "hoeken-coordinates.yaml").to_dict()
    model["points"]["O4"] = ["3.937007874015748 in", "0 ft"]
    model["coordinates"][0]["value"] = "180 deg"
    mech = pdy.from_dict(model)
    assert points(mech)["O4"][0] == pytest.approx(3.937007874015748 * 0.0254, rel=1e-16)
    assert mech.drawn_q[0] == pytest.approx(math.pi, rel=1e-16)


def test_errors_name_the_field_and_the_fix(page):
    text = (page["folder"] / "hoeken.yaml").read_text()
    with pytest.raises(pdy.ModelError) as e:
        pdy.loads(text.replace('"180 deg"', '"180 degs"'), source="hoeken.yaml")
    assert str(e.value) == ("hoeken.yaml: points.A.angle: \"180 degs\": 'degs' is not a unit of an angle (rad, deg, "
                            "rev, or a number alone in rad) (line 6 column 41); write e.g. \"30 deg\"")
    # |A O4| = 150 mm at the drawing, 125 + 20 = 145 mm: 5 mm short.
    with pytest.raises(pdy.ModelError) as e:
        pdy.loads(text.replace('[O4, "125 mm"]', '[O4, "20 mm"]'), source="hoeken.yaml")
    assert str(e.value).startswith("hoeken.yaml: points.B: the circles of radius 0.125 m about A and 0.02 m about O4 "
                                   "do not meet: their centres are 0.15 m apart, more than the sum of the radii 0.145 "
                                   "by 5.000000e-3 m (line 7 column 6); change a radius by at least that, or move a centre")


def test_check_prints_the_derived_dimensions(page, capsys):
    assert cli.main(["check", str(page["folder"] / "hoeken.yaml")]) == 0
    out = capsys.readouterr().out
    assert "  crank: O2-A 0.05; O2->A at 180 deg\n" in out
    assert "  coupler: A-P 0.25, A-B 0.125; A->P at 53.1301 deg\n" in out  # atan(4/3)
    assert "points by construction:\n  A = (-0.05, 0)\n  B = (0.025, 0.1)\n  P = (0.1, 0.2)\n" in out


def test_the_builder_names_what_it_lacks():
    b = pdy.Builder("x")
    b.point("O", (0, 0))
    b.polar("A", "O", "10 mm", "30 deg")
    np.testing.assert_allclose(b.xy("A"), (0.01 * math.cos(math.pi / 6), 0.005), rtol=0, atol=1e-15)
    with pytest.raises(pdy.ArgumentError, match=r"unknown point 'B'; the points so far: O, A \(add it first\)"):
        b.xy("B")
    with pytest.raises(pdy.ArgumentError, match="unknown body 'crank'"):
        b.carry("crank", "A")
    with pytest.raises(pdy.ArgumentError, match="give one of mass"):
        b.bar("crank", ["O", "A"])
    b.polar("C", "Q", 1, 0)
    with pytest.raises(pdy.ModelError, match=r"points.C: unknown point 'Q'"):
        b.xy("C")


# ----------------------------------------------------------------------------- drawings


def test_dxf_drawing_reads_back_in_millimetres(tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    mech = pdy.load(DATA / "shaper.yaml")
    path = write_drawing(mech, tmp_path / "shaper.dxf")
    doc = ezdxf.readfile(path)
    assert doc.units == ezdxf.units.MM
    msp = doc.modelspace()
    where = {n: p * MM_PER_M for n, p in points(mech).items()}
    lines = [(e.dxf.start, e.dxf.end) for e in msp.query('LINE[layer=="BODIES"]')]
    assert len(lines) == 4  # crank, lever, link, ram: two points each
    for (start, end), (p, q) in zip(lines, (("O2", "A"), ("O1", "B"), ("B", "C"), ("C", "T"))):
        np.testing.assert_allclose([start.x, start.y, end.x, end.y], [*where[p], *where[q]], rtol=0, atol=1e-9)
    labels = {e.dxf.text: (e.dxf.insert.x, e.dxf.insert.y) for e in msp.query('TEXT[layer=="LABELS"]')}
    assert set(labels) == set(mech.point_names)
    np.testing.assert_allclose(labels["T"], where["T"], rtol=0, atol=1e-9)
    # Pins: the four revolute pairs and the slot's pin, circles of 1.5 % of the drawing's size.
    pins = [e for e in msp.query('CIRCLE[layer=="PAIRS"]')]
    assert len(pins) == 5
    # Ground marks under the two pivots O1, O2 (G, H only lay the ram's guide).
    assert len(msp.query('LWPOLYLINE[layer=="GROUND"]')) == 2


def test_svg_drawing_parses_with_its_labels(page, tmp_path):
    mech = pdy.load(page["folder"] / "hoeken.yaml")
    path = write_drawing(mech, tmp_path / "hoeken.svg")
    root = ET.parse(path).getroot()
    assert root.tag == "{http://www.w3.org/2000/svg}svg"
    texts = {"".join(t.itertext()).strip() for t in root.iter("{http://www.w3.org/2000/svg}text")}
    assert set(mech.point_names) <= texts
    assert "Hoeken straight-line linkage" in texts
    # No date, fixed ids: the same drawing gives the same file (docs/img/hoeken.svg is this one).
    assert write_drawing(mech, tmp_path / "again.svg").read_bytes() == path.read_bytes()
    assert path.read_bytes() == (ROOT / "docs" / "img" / "hoeken.svg").read_bytes(), (
        "docs/img/hoeken.svg is not what `planardyn draw hoeken.yaml -o hoeken.svg` writes (with docs/dimensions.md's "
        "hoeken.yaml): write it again")


def test_draw_command_writes_both_and_refuses_other_suffixes(tmp_path, capsys):
    for suffix in (".svg", ".dxf"):
        out = tmp_path / f"d{suffix}"
        assert cli.main(["draw", str(DATA / "shaper.yaml"), "-o", str(out)]) == 0
        assert out.stat().st_size > 0
    assert cli.main(["draw", str(DATA / "shaper.yaml"), "-o", str(tmp_path / "d.png")]) == 2
    assert "give a file ending in .svg or .dxf" in capsys.readouterr().err
