"""Exchange formats: import after export gives the same mechanism; the URDF and SDF exports
load in parsers of their formats; import errors name the element and its line; the CLI.

Round trip: the mass matrix A(q) and the forward dynamics qdd(q, qd) (efforts 0, every load
acting) at the start state and at a state moved along the motion agree to ROUND_OFF, and
every drawn point of the original is where the import puts it.
"""

from __future__ import annotations

import io
import warnings

import numpy as np
import planardyn as pdn
import pytest
from planardyn import models
from planardyn.cli import main
from planardyn.exchange import ExchangeError, from_mjcf, from_urdf, to_mjcf, to_sdf, to_urdf

#: Relative agreement of A and qdd after a round trip: the files hold every number at full
#: precision (repr), so what is left is the round-off of rebuilding the drawing (the worst
#: measured, Andrews' squeezer's qdd, is 2e-12 relative to its size).
ROUND_OFF = 1e-9
NAMES = models.names()
#: The shipped models with losses no format carries, and what each export's header lists of
#: them (docs/exchange.md): their MJCF comes back, and runs in MuJoCo, in the lossless form.
LOSSY: dict[str, list[str]] = {
    "five-bar-robot": [*(f"Coulomb friction at pair {p!r} (mu = 0.1)" for p in ("elbow1", "effector", "elbow2")),
                       *(f"the {what} of actuator {c!r}" for c in ("theta1", "theta2")
                         for what in ("efficiency 0.8", "back-drive efficiency 0.75"))],
    # the compliance section feeds the stiffness and vibration analyses only; no export carries it
    "five-bar-compliant": ["the elastic drive of actuator 'theta1' (stiffness 2000.0)",
                           "the elastic drive of actuator 'theta2' (stiffness 3000.0)",
                           "the compliance of pair 'effector' (stiffness 500000.0)"],
}


def _load(name: str) -> pdn.Mechanism:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pdn.PlanardynWarning)  # the double parallelogram's redundancy
        return pdn.load_example(name)


def lossless(mech: pdn.Mechanism) -> pdn.Mechanism:
    """The model without what the formats cannot carry (docs/exchange.md, *What cannot map*):
    Coulomb pair friction, actuator efficiencies (both ways)."""
    spec = mech.to_dict()
    spec["loads"] = [ld for ld in spec.get("loads", []) if not (ld["type"] == "friction" and ld.get("mu"))]
    for a in spec.get("actuators", []):
        a["efficiency"] = 1.0
        a.pop("backdrive_efficiency", None)
    return pdn.from_dict(spec)


def _same_mechanism(orig: pdn.Mechanism, back: pdn.Mechanism) -> None:
    res = orig.simulate(t_end=0.05, t_eval=[0.0, 0.05])
    for q, qd in zip(res.q, res.qd):
        a0, a1 = orig.mass_matrix(q, allow_singular=True), back.mass_matrix(q, allow_singular=True)
        assert np.max(np.abs(a1 - a0)) <= ROUND_OFF * np.max(np.abs(a0))
        tau = np.zeros(orig.dof)
        f0 = orig.forward_dynamics(q, qd, tau=tau, allow_singular=True)
        f1 = back.forward_dynamics(q, qd, tau=tau, allow_singular=True)
        assert np.max(np.abs(f1 - f0)) <= ROUND_OFF * max(1.0, np.max(np.abs(f0)))
    drawn = dict(zip(orig.point_names, orig.point_positions(orig.x0)))
    again = dict(zip(back.point_names, back.point_positions(back.x0)))
    for name, p in drawn.items():
        assert np.max(np.abs(again[name] - p)) <= ROUND_OFF * orig.scale, name


@pytest.mark.parametrize("name", NAMES)
def test_mjcf_round_trip(name):
    """A model with losses MJCF cannot carry comes back in its lossless form."""
    orig = _load(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pdn.PlanardynWarning)
        back = pdn.from_dict(from_mjcf(to_mjcf(orig), name))
    assert back.coordinate_names == orig.coordinate_names
    np.testing.assert_allclose(back.q0, orig.q0, rtol=0, atol=ROUND_OFF)
    np.testing.assert_allclose(back.qd0, orig.qd0, rtol=0, atol=ROUND_OFF)
    _same_mechanism(lossless(orig) if name in LOSSY else orig, back)


@pytest.mark.parametrize("name", NAMES)
def test_urdf_round_trip(name):
    """URDF carries no coordinate offsets, gravity, springs or constant loads: the
    comparison takes the original's coordinates and leaves those out of the original."""
    spec = _load(name).to_dict()
    spec["gravity"] = [0.0, 0.0]
    spec["loads"] = [ld for ld in spec.get("loads", []) if ld["type"] in ("friction",) and ld.get("viscous")
                     and not ld.get("mu")]
    spec["actuators"] = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pdn.PlanardynWarning)
        orig = pdn.from_dict(spec)
        model = from_urdf(to_urdf(orig), name, coordinates=[c["pair"] for c in spec["coordinates"]])
        values = {c["pair"]: c["value"] for c in spec["coordinates"]}
        for c in model["coordinates"]:
            c["value"] = values[c["pair"]]
        back = pdn.from_dict(model)
    _same_mechanism(orig, back)


@pytest.mark.parametrize("name", NAMES)
def test_urdf_loads_in_urdf_parsers(name):
    """yourdfpy and urdf_parser_py read the tree and skip the <gazebo> closing joints."""
    yourdfpy = pytest.importorskip("yourdfpy")
    from urdf_parser_py.urdf import URDF



    mech = _load(name)
    text = to_urdf(mech)
    robot = yourdfpy.URDF.load(io.BytesIO(text.encode()), load_meshes=False, build_scene_graph=True)
    tree_joints = {j.name for j in robot.robot.joints}
    parsed = URDF.from_xml_string(text.encode())
    assert {j.name for j in parsed.joints} == tree_joints
    # one link per body, plus world and a carriage per slot; a tree: one joint less than links
    slots = sum(1 for p in mech.pairs if p["kind"] == "slot")
    assert len(robot.robot.links) == mech.n_bodies + 1 + slots
    assert len(tree_joints) == len(robot.robot.links) - 1


# SDFormat 1.11's rules for the elements the export writes (sdf/1.11/{root,world,model,link,
# inertial,joint,mimic}.sdf of gazebosim/sdformat): the children each may hold, the ones it
# must hold, and the type of its text. python-sdformat parses SDF but pins lxml < 5 and
# numpy < 2, which this environment does not take; the rules are checked here instead.
SDF_CHILDREN = {
    "sdf": {"world"}, "world": {"gravity", "model"}, "model": {"link", "joint"},
    "link": {"pose", "inertial"}, "inertial": {"pose", "mass", "inertia"},
    "inertia": {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"},
    "joint": {"parent", "child", "pose", "axis"}, "axis": {"xyz", "dynamics", "limit", "mimic"},
    "dynamics": {"damping", "friction", "spring_reference", "spring_stiffness"}, "limit": {"lower", "upper"},
    "mimic": {"multiplier", "offset", "reference"},
}
SDF_REQUIRED = {"joint": {"parent", "child"}, "axis": {"xyz", "limit"}, "limit": {"lower", "upper"},
                "inertia": {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"},
                "dynamics": {"spring_reference", "spring_stiffness"}, "mimic": {"multiplier", "offset", "reference"}}
SDF_NUMBERS = {"gravity": 3, "pose": 6, "xyz": 3, "mass": 1, "damping": 1, "friction": 1, "spring_reference": 1,
               "spring_stiffness": 1, "lower": 1, "upper": 1, "multiplier": 1, "offset": 1, "reference": 1,
               "ixx": 1, "ixy": 1, "ixz": 1, "iyy": 1, "iyz": 1, "izz": 1}
SDF_JOINT_TYPES = {"continuous", "revolute", "gearbox", "revolute2", "prismatic", "ball", "screw", "universal", "fixed"}


def _check_sdf(el, links, joints):
    for child in el:
        assert child.tag in SDF_CHILDREN.get(el.tag, set()), f"<{child.tag}> in <{el.tag}>"
        _check_sdf(child, links, joints)
    assert SDF_REQUIRED.get(el.tag, set()) <= {c.tag for c in el}, f"<{el.tag}> lacks a required child"
    if el.tag in SDF_NUMBERS:
        assert len([float(v) for v in el.text.split()]) == SDF_NUMBERS[el.tag]
    if el.tag == "joint":
        assert el.get("type") in SDF_JOINT_TYPES and el.get("name")
        assert el.findtext("parent") in links | {"world"} and el.findtext("child") in links
    if el.tag == "mimic":
        assert el.get("joint") in joints


@pytest.mark.parametrize("name", NAMES)
def test_sdf_follows_the_spec_and_keeps_every_pair(name):
    import xml.etree.ElementTree as ET

    mech = _load(name)
    root = ET.fromstring(to_sdf(mech))
    assert root.tag == "sdf" and root.get("version") == "1.11"
    model = root.find("world/model")
    links = {link.get("name") for link in model.findall("link")}
    joints = {j.get("name") for j in model.findall("joint")}
    _check_sdf(root, links, joints)
    # a graph: every revolute and prismatic pair a joint, a slot two (with its carriage link)
    kinds = [p["kind"] for p in mech.pairs]
    assert len(joints) == kinds.count("revolute") + kinds.count("prismatic") + 2 * kinds.count("slot")
    assert len(links) == mech.n_bodies + kinds.count("slot")
    assert len(model.findall("joint/axis/mimic")) == kinds.count("gear")


def test_import_errors_name_the_element_and_line():
    xml = to_mjcf(_load("four-bar-gravity")).replace('type="hinge"', 'type="ball"', 1)
    line = 1 + xml[:xml.index('type="ball"')].count("\n")
    with pytest.raises(ExchangeError, match=rf"<string>: line {line}: <joint name='ground_crank'>: a ball joint is not planar"):
        from_mjcf(xml)
    tilted = to_mjcf(_load("four-bar-gravity")).replace('axis="0 0 1.0"', 'axis="1 0 0"', 1)
    with pytest.raises(ExchangeError, match="does not turn about the z axis"):
        from_mjcf(tilted)
    with pytest.raises(ExchangeError, match=r"line 1 column 8: not well-formed XML: mismatched tag"):
        from_mjcf("<a><b></a>")
    urdf = to_urdf(_load("four-bar-gravity")).replace('type="continuous"', 'type="floating"', 1)
    with pytest.raises(ExchangeError, match=r"a floating joint is not planar"):
        from_urdf(urdf)


def test_cli_export_and_import(tmp_path, capsys):
    out = tmp_path / "four-bar.xml"
    assert main(["export", "four-bar-gravity", "-o", str(out)]) == 0
    assert main(["import", str(out), "-o", str(tmp_path / "four-bar.yaml")]) == 0
    back = pdn.load(tmp_path / "four-bar.yaml")
    orig = _load("four-bar-gravity")
    np.testing.assert_allclose(back.mass_matrix(orig.q0), orig.mass_matrix(orig.q0), rtol=ROUND_OFF)
    assert main(["export", "four-bar-gravity", "-o", str(tmp_path / "x.txt")]) == 2
    assert "the extension must be one of .xml, .mjcf, .urdf, .sdf" in capsys.readouterr().err
    # A timestep MuJoCo cannot step by: refused, no file written (before: timestep="nan" in it).
    for bad in ("nan", "inf", "0", "-1e-3"):
        assert main(["export", "four-bar-gravity", "-o", str(tmp_path / "bad.xml"), "--timestep", bad]) == 2
        assert "timestep" in capsys.readouterr().err and not (tmp_path / "bad.xml").exists()
    with pytest.raises(pdn.ArgumentError, match=r"timestep = nan must be a finite number > 0 \(s\)"):
        to_mjcf(_load("four-bar-gravity"), timestep=float("nan"))


@pytest.mark.parametrize("name", sorted(LOSSY))
def test_a_lossy_models_exports_list_what_they_leave_out(name):
    mech = _load(name)
    for text in (to_mjcf(mech), to_urdf(mech), to_sdf(mech)):
        header = text[:text.index("-->")]
        missing = [item for item in LOSSY[name] if item not in header]
        assert not missing, missing
