"""URDF (ROS's robot description): export the spanning tree, the closing joints in the
``<gazebo>`` extension; import the same, the planar subset.

URDF is a tree (urdfdom refuses a link with two parents), so the closing pairs follow the
convention of the Gazebo tutorial "Model a 4-bar linkage in SDFormat and URDF" and of
sdformat's URDF extension: an SDF ``<joint>`` inside a ``<gazebo>`` element at the top of
the robot. URDF parsers (urdfdom, yourdfpy, urdf_parser_py) skip ``<gazebo>``; sdformat's
URDF-to-SDF conversion (``gz sdf -p``, Gazebo) inserts the joint into the model, closing the
loop. docs/exchange.md lists the other conventions found and why this one.

The root link is ``world`` (planardyn's ground; sdformat fixes it to the world). Joint
origins put each child frame at the point of its pair, with the axes of the drawing; a
revolute pair is a ``continuous`` joint, a prismatic pair a ``prismatic`` one, a slot a
``prismatic`` joint into a massless carriage link and a ``continuous`` one at the pin, a gear
pair a ``<mimic>`` on the follower's joint, an actuator a ``<transmission>`` with its
mechanical reduction. Each point of a body is a small named sphere in its link's visuals,
which gives the importer the points back and draws the mechanism in RViz.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Any

import numpy as np

from ..mechanism import Mechanism
from .mjcf import AXIS_TOL
from .planar import Builder
from .sdf import carriage, closing_joint, edge_joints, header, link_name
from .tree import GROUND, Drawing, ExchangeError, Vec, actuated, drawing, not_carried, pair_loads
from .xmltext import Document, num, nums, parse, text

#: URDF requires effort, velocity and travel limits on a prismatic joint; planardyn's pairs
#: have none, so they are written this large (SI units).
UNLIMITED = 1e9
#: Radius of the spheres marking the points, a fraction of the mechanism's size (visual only).
POINT_RADIUS = 0.01
#: The prefix of a visual that marks a point.
POINT = "point:"


def to_urdf(mech: Mechanism) -> str:
    """The URDF text of a mechanism.

    Raises
    ------
    ExchangeError
        As :func:`planardyn.exchange.to_mjcf`.
    """
    d = drawing(mech)
    robot = ET.Element("robot", name=d.name)
    lost = not_carried(d) + [f"the {ld['type']} load {k}" for k, ld in enumerate(d.spec.get("loads", []))
                             if ld["type"] in ("spring", "force", "torque")]
    lost += ["the torsional springs (URDF joints have damping and friction only)"] * any(
        "stiffness" in t for t in pair_loads(d).values())
    lost += ["the rotor inertias (no URDF element)"] * any(a.get("rotor_inertia") for a in d.spec.get("actuators", []))
    lost += ["gravity (a world's property)"]
    robot.append(ET.Comment(header(d, "URDF", lost)))
    ET.SubElement(robot, "link", name="world")
    _points(d, robot.find("link"), GROUND)  # type: ignore[arg-type]  # just made
    for body in d.bodies.values():
        link = ET.SubElement(robot, "link", name=body.name)
        inertial = ET.SubElement(link, "inertial")
        ET.SubElement(inertial, "origin", xyz=_v(d.local(body.name, body.com)), rpy="0 0 0")
        ET.SubElement(inertial, "mass", value=num(body.mass))
        i = num(body.inertia)
        ET.SubElement(inertial, "inertia", ixx=i, ixy="0", ixz="0", iyy=i, iyz="0", izz=i)
        _points(d, link, body.name)
    loads = pair_loads(d)
    joints: dict[str, ET.Element] = {}
    for e in d.edges:
        if e.pair.kind == "slot":
            ET.SubElement(robot, "link", name=carriage(e.pair))
        for k, (name, kind, parent, child, axis) in enumerate(edge_joints(e)):
            j = ET.SubElement(robot, "joint", name=name, type="continuous" if kind == "hinge" else "prismatic")
            ET.SubElement(j, "parent", link=link_name(parent))
            ET.SubElement(j, "child", link=child)
            at = d.origin[e.child] - d.origin[e.parent] if k == 0 else np.zeros(2)
            ET.SubElement(j, "origin", xyz=_v(at), rpy="0 0 0")
            ET.SubElement(j, "axis", xyz=nums(axis))
            if kind == "slide":
                ET.SubElement(j, "limit", effort=num(UNLIMITED), velocity=num(UNLIMITED),
                              lower=num(-UNLIMITED), upper=num(UNLIMITED))
            if kind == ("hinge" if e.pair.kind == "revolute" else "slide") and loads.get(e.pair.name, {}).get("damping"):
                ET.SubElement(j, "dynamics", damping=num(loads[e.pair.name]["damping"]), friction="0")
            joints[name] = j
    for c in d.couplings:
        ET.SubElement(joints[c.follower.pair.name], "mimic", joint=c.leader.pair.name, multiplier=num(c.ratio), offset="0")
    for pair, act, _ in actuated(d):
        if pair in joints:
            _transmission(robot, pair, float(act.get("gear_ratio", 1.0)) if act else 1.0)
    if d.closing:
        gazebo = ET.SubElement(robot, "gazebo")
        for p in d.closing:
            gazebo.append(closing_joint(d, p))
    return text(robot)


def _v(p: Vec) -> str:
    return nums((p[0], p[1], 0.0))


def _points(d: Drawing, link: ET.Element, body: str) -> None:
    names = d.mech.ground_points if body == GROUND else d.bodies[body].points
    for point in names:
        visual = ET.SubElement(link, "visual", name=f"{POINT}{point}")
        ET.SubElement(visual, "origin", xyz=_v(d.local(body, d.points[point])), rpy="0 0 0")
        ET.SubElement(ET.SubElement(visual, "geometry"), "sphere", radius=num(POINT_RADIUS * d.mech.scale))


def _transmission(robot: ET.Element, joint: str, n: float) -> None:
    """ROS's simple transmission: the motor turns n times the joint."""
    t = ET.SubElement(robot, "transmission", name=f"{joint}_transmission")
    ET.SubElement(t, "type").text = "transmission_interface/SimpleTransmission"
    ET.SubElement(ET.SubElement(t, "joint", name=joint), "hardwareInterface").text = "hardware_interface/EffortJointInterface"
    act = ET.SubElement(t, "actuator", name=f"{joint}_motor")
    ET.SubElement(act, "mechanicalReduction").text = num(n)


# ------------------------------------------------------------------ import


def _rpy(doc: Document, el: ET.Element | None) -> tuple[Vec, np.ndarray]:
    """An <origin>'s translation (3,) and rotation (3x3): R = Rz(yaw) Ry(pitch) Rx(roll)."""
    if el is None:
        return np.zeros(3), np.eye(3)
    from scipy.spatial.transform import Rotation

    xyz = np.array(doc.floats(el, "xyz", 3, "0 0 0"))
    return xyz, Rotation.from_euler("xyz", doc.floats(el, "rpy", 3, "0 0 0")).as_matrix()


def from_urdf(data: str, source: str = "<string>", coordinates: list[str] | None = None) -> dict[str, Any]:
    """A planardyn model dict from URDF text with its ``<gazebo>`` closing joints.

    Parameters
    ----------
    data, source
        The URDF text and its name for messages.
    coordinates
        Joint names to take as the coordinates, in order; default: the joints with a
        transmission, then the tree joints in the file's order, each kept when independent.

    Raises
    ------
    ExchangeError
        A joint that is not a planar hinge or slide, a massive link missing its inertial, a
        link with two parents, named with its line.
    """
    doc = parse(data, source)
    if doc.root.tag != "robot":
        raise doc.error(doc.root, "not a URDF file: the root element must be <robot>")
    out = Builder(doc.root.get("name", "imported"), source)
    links = {el.get("name", ""): el for el in doc.root.findall("link")}
    joints = doc.root.findall("joint")
    parent_of: dict[str, ET.Element] = {}
    for j in joints:
        child = j.find("child")
        name = child.get("link", "") if child is not None else ""
        if name in parent_of:
            raise doc.error(j, f"link {name!r} has a second parent: URDF is a tree; close loops with an SDF joint "
                               "inside <gazebo> (see `planardyn docs exchange`)")
        parent_of[name] = j
    roots = [n for n in links if n not in parent_of]
    if len(roots) != 1:
        raise doc.error(doc.root, f"a URDF tree has one root link, this file has {roots}")
    r = _UrdfReader(doc, out, links, joints)
    r.walk(roots[0], GROUND, np.zeros(3), np.eye(3))
    out.masses(source)
    for g in doc.root.findall("gazebo"):
        for j in g.findall("joint"):
            r.closing(j)
    for j in joints:
        mimic = j.find("mimic")
        if mimic is not None:
            r.gear(j, mimic)
    out.preferred = coordinates or [t.find("joint").get("name", "") for t in doc.root.findall("transmission")  # type: ignore[union-attr]
                                    if t.find("joint") is not None]
    out.preferred = [r.pair_of.get(n, n) for n in out.preferred]
    if coordinates:
        out.choose_coordinates()
        missing = [c for c in out.preferred if c not in {x["pair"] for x in out.coordinates}]
        if missing:
            raise ExchangeError(f"{source}: joints {missing} are not independent coordinates of this mechanism")
    return out.model()


class _UrdfReader:
    """Walks a URDF tree into a Builder; a massless link between a prismatic and a continuous
    joint is a slot's carriage, a fixed joint merges its child into its parent's body."""

    def __init__(self, doc: Document, out: Builder, links: dict[str, ET.Element], joints: list[ET.Element]) -> None:
        self.doc, self.out, self.links, self.joints = doc, out, links, joints
        self.frames: dict[str, tuple[str, Vec, np.ndarray]] = {}  # link -> (planardyn body, p, R)
        self.pair_of: dict[str, str] = {}  # URDF joint -> pair

    def points(self, link: str, body: str, p: Vec, r: np.ndarray) -> None:
        """The link's marked points, and its inertial as a part of the body."""
        el = self.links.get(link)
        if el is None:
            raise self.doc.error(self.doc.root, f"link {link!r} is named by a joint but not defined")
        for v in el.findall("visual"):
            if v.get("name", "").startswith(POINT):
                vp, _ = _rpy(self.doc, v.find("origin"))
                self.out.point(body, v.get("name", "").removeprefix(POINT), (p + r @ vp)[:2])
        inertial = el.find("inertial")
        if inertial is not None and link not in self.frames:
            op, orr = _rpy(self.doc, inertial.find("origin"))
            i, m = inertial.find("inertia"), inertial.find("mass")
            if i is None or m is None:
                raise self.doc.error(inertial, "an <inertial> needs <mass> and <inertia>")
            f = {k: float(i.get(k, 0.0)) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")}
            tensor = np.array([[f["ixx"], f["ixy"], f["ixz"]], [f["ixy"], f["iyy"], f["iyz"]], [f["ixz"], f["iyz"], f["izz"]]])
            rot = r @ orr
            self.out.part(body, float(m.get("value", 0.0)), float((rot @ tensor @ rot.T)[2, 2]), p + r @ op)
        self.frames[link] = (body, p, r)

    def walk(self, link: str, body: str, p: Vec, r: np.ndarray, carriage: tuple | None = None) -> None:
        """A link and, depth first, the links below it."""
        self.points(link, body, p, r)
        for j in self.joints:
            parent = j.find("parent")
            if parent is None or parent.get("link") != link:
                continue
            child = j.find("child").get("link", "")  # type: ignore[union-attr]  # from_urdf checked it
            jp, jr = _rpy(self.doc, j.find("origin"))
            cp, cr = p + r @ jp, r @ jr
            kind = {"continuous": "hinge", "revolute": "hinge", "prismatic": "slide", "fixed": "fixed"}.get(j.get("type", ""))
            if kind is None:
                raise self.doc.error(j, f"a {j.get('type')} joint is not planar: planardyn reads revolute, continuous, "
                                        "prismatic and fixed joints")
            if kind == "fixed":
                self.walk(child, body, cp, cr, carriage)
                continue
            ax = j.find("axis")
            axis = cr @ np.array(self.doc.floats(ax, "xyz", 3) if ax is not None else [1.0, 0.0, 0.0])
            axis /= np.linalg.norm(axis)
            if (np.linalg.norm(axis[:2]) if kind == "hinge" else abs(axis[2])) > AXIS_TOL:
                raise self.doc.error(j, f"its axis {axis.round(12).tolist()} is not planar (hinges about z, slides in x-y)")
            massive = self.links.get(child, j).find("inertial") is not None
            if not massive and carriage is None:
                self.walk(child, body, cp, cr, (j, kind, cp[:2], axis))
                continue
            self.points(child, child, cp, cr)
            self.pair(j, kind, body, child, cp[:2], axis, carriage)
            self.walk(child, child, cp, cr)

    def pair(self, j: ET.Element, kind: str, body: str, child: str, at: Vec, axis: Vec, carriage: tuple | None) -> None:
        name = j.get("name", "").split(".")[0]
        if carriage is None and kind == "hinge":
            bodies = [body, child] if axis[2] > 0 else [child, body]
            self.out.pair("revolute", name, bodies[0], bodies[1], self.out.share(body, self.out.point(child, name, at)))
        elif carriage is None:
            self.out.pair("prismatic", name, body, child, self.out.point(child, name, at), axis)
        elif (carriage[1], kind) == ("slide", "hinge"):  # the slot on the parent, the pin on the child
            self.out.pair("slot", name, body, child, self.out.point(child, name, at), carriage[3])
        elif (carriage[1], kind) == ("hinge", "slide"):  # the slot on the child, about the parent's pin
            self.out.pair("slot", name, child, body, self.out.point(body, name, carriage[2]), -axis)
        else:
            raise self.doc.error(j, "a massless link must join a prismatic and a revolute joint (a slot)")
        for joint in ([carriage[0]] if carriage else []) + [j]:
            self.pair_of[joint.get("name", "")] = name
            damping = float(joint.find("dynamics").get("damping", 0.0)) if joint.find("dynamics") is not None else 0.0
            if damping and (len(self.pair_of) and (carriage is None or joint.get("type") == "prismatic")):
                self.out.loads.append({"type": "friction", "pair": name, "viscous": damping})

    def closing(self, j: ET.Element) -> None:
        """An SDF joint in <gazebo>: a closing revolute pair (pose in the child's frame)."""
        if j.get("type") not in ("revolute", "continuous"):
            raise self.doc.error(j, "planardyn closes loops with revolute joints only")
        ends = [j.findtext(k, "").strip() for k in ("parent", "child")]
        if not all(e in self.frames for e in ends):
            raise self.doc.error(j, f"parent and child {ends} must be links of the tree")
        pose = j.find("pose")
        if pose is not None and pose.get("relative_to", ends[1]) != ends[1]:
            raise self.doc.error(pose, "a closing joint's pose is read relative to its child link only")
        xyz = np.array([float(v) for v in (pose.text or "0 0 0").split()[:3]]) if pose is not None else np.zeros(3)
        axis = np.array([float(v) for v in j.findtext("axis/xyz", "0 0 1").split()])
        (a, _, _), (b, pb, rb) = self.frames[ends[0]], self.frames[ends[1]]
        if np.linalg.norm((rb @ axis)[:2]) > AXIS_TOL * np.linalg.norm(axis):
            raise self.doc.error(j, "its axis does not turn about z (planar subset)")
        at = (pb + rb @ xyz)[:2]
        name = j.get("name", "")
        self.out.pair("revolute", name, a, b, self.out.share(a, self.out.point(b, name, at)))

    def gear(self, j: ET.Element, mimic: ET.Element) -> None:
        follow, lead = self.pair_of.get(j.get("name", "")), self.pair_of.get(mimic.get("joint", ""))
        if follow is None or lead is None or float(mimic.get("offset", 0.0)):
            raise self.doc.error(mimic, "a mimic couples two planar joints of the tree, without offset")
        why = self.out.gear(f"{follow}_gear", follow, lead, float(mimic.get("multiplier", 1.0)))
        if why:
            raise self.doc.error(mimic, why)
