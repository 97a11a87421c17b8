"""SDF (SDFormat 1.11, Gazebo's format): export a mechanism as a world holding its model.

SDF models are graphs: every pair is a ``<joint>`` between two links, the closing ones
included, which is why URDF files carry their closing joints as SDF joints (urdf.py).
Links sit at the frames of :mod:`.tree` (the point of their tree pair, axes of the drawing);
a joint's pose is relative to its child link (SDF's default), its axis in the joint frame.
Gear pairs are ``<mimic>`` constraints (SDF 1.11) on the follower's axis; a slot is a
prismatic joint into a carriage link and a revolute joint at the pin; gravity is the world's.
What cannot map (springs between points, constant loads, motors) is listed in a comment.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from ..mechanism import Mechanism
from .tree import GROUND, Drawing, Edge, Pair, actuated, drawing, not_carried, pair_loads
from .xmltext import num, nums, text

VERSION = "1.11"
#: A slot's carriage link has no mass in planardyn; SDF gives a link without <inertial>
#: 1 kg, so the carriage gets this fraction of the lightest body's mass and inertia.
CARRIAGE_FRACTION = 1e-6


def carriage(pair: Pair) -> str:
    """The name of a slot's carriage link (the slide's child, the hinge's parent)."""
    return f"{pair.name}.carriage"


def link_name(body: str) -> str:
    return "world" if body == GROUND else body


def joint(name: str, kind: str, parent: str, child: str, pose: np.ndarray, axis: np.ndarray,
          terms: dict[str, float] | None = None) -> ET.Element:
    """An SDF joint: kind 'revolute' or 'prismatic', pose (2,) of the joint in the child's
    frame (m), axis (3,) in the joint frame, optional dynamics (damping, spring)."""
    j = ET.Element("joint", name=name, type=kind)
    ET.SubElement(j, "parent").text = link_name(parent)
    ET.SubElement(j, "child").text = link_name(child)
    ET.SubElement(j, "pose").text = nums((pose[0], pose[1], 0.0, 0.0, 0.0, 0.0))
    ax = ET.SubElement(j, "axis")
    ET.SubElement(ax, "xyz").text = nums(axis)
    if terms:
        dyn = ET.SubElement(ax, "dynamics")
        ET.SubElement(dyn, "damping").text = num(terms.get("damping", 0.0))
        ET.SubElement(dyn, "spring_reference").text = num(terms.get("rest", 0.0))
        ET.SubElement(dyn, "spring_stiffness").text = num(terms.get("stiffness", 0.0))
    lim = ET.SubElement(ax, "limit")  # planardyn's pairs have no stops
    ET.SubElement(lim, "lower").text = "-inf"
    ET.SubElement(lim, "upper").text = "inf"
    return j


def edge_joints(e: Edge) -> list[tuple[str, str, str, str, np.ndarray]]:
    """The one-axis joints of a tree edge as (name, 'hinge' | 'slide', parent link, child
    link, axis (3,)), with a slot's carriage link between its two joints."""
    names = [f"{e.pair.name}.{k}" for k in e.joints] if e.pair.kind == "slot" else [e.pair.name]
    links = [e.parent, carriage(e.pair), e.child] if e.pair.kind == "slot" else [e.parent, e.child]
    return [(name, kind, links[k], links[k + 1], e.axis(kind)) for k, (name, kind) in enumerate(zip(names, e.joints))]


def closing_joint(d: Drawing, p: Pair) -> ET.Element:
    """A closing revolute pair as an SDF joint (pose in b's frame, at the pin)."""
    return joint(p.name, "revolute", p.a, p.b, d.local(p.b, d.points[p.point]), np.array([0.0, 0.0, 1.0]),
                 pair_loads(d).get(p.name))


def mimic(follower: ET.Element, leader: str, ratio: float) -> None:
    """A gear pair's coupling on the follower joint's axis (SDF 1.11 ``mimic``)."""
    m = ET.SubElement(follower.find("axis"), "mimic", joint=leader)  # type: ignore[arg-type]  # joint() made it
    ET.SubElement(m, "multiplier").text = num(ratio)
    ET.SubElement(m, "offset").text = "0"
    ET.SubElement(m, "reference").text = "0"


def to_sdf(mech: Mechanism) -> str:
    """The SDF text of a mechanism: a world (with its gravity) holding the model.

    Raises
    ------
    ExchangeError
        As :func:`planardyn.exchange.to_mjcf`.
    """
    d = drawing(mech)
    sdf = ET.Element("sdf", version=VERSION)
    world = ET.SubElement(sdf, "world", name=f"{d.name} world")
    ET.SubElement(world, "gravity").text = nums((*mech.gravity, 0.0))
    model = ET.SubElement(world, "model", name=d.name)
    model.append(ET.Comment(_header(d)))
    lightest = min(b.mass for b in d.bodies.values())
    for body in d.bodies.values():
        _link(model, body.name, d.origin[body.name], body.com - d.origin[body.name], body.mass, body.inertia)
    loads = pair_loads(d)
    joints: dict[str, ET.Element] = {}
    for e in d.edges:
        if e.pair.kind == "slot":
            small = CARRIAGE_FRACTION * lightest
            _link(model, carriage(e.pair), d.points[e.pair.point], np.zeros(2), small, small * mech.scale**2)
        for name, kind, parent, child, axis in edge_joints(e):
            own = kind == ("hinge" if e.pair.kind == "revolute" else "slide")
            joints[name] = joint(name, "revolute" if kind == "hinge" else "prismatic", parent, child, np.zeros(2), axis,
                                 loads.get(e.pair.name) if own else None)
            model.append(joints[name])
    for p in d.closing:
        model.append(closing_joint(d, p))
    for c in d.couplings:
        mimic(joints[c.follower.pair.name], c.leader.pair.name, c.ratio)
    return text(sdf)


def _link(model: ET.Element, name: str, origin: np.ndarray, com: np.ndarray, mass: float, inertia: float) -> None:
    link = ET.SubElement(model, "link", name=name)
    ET.SubElement(link, "pose").text = nums((origin[0], origin[1], 0.0, 0.0, 0.0, 0.0))
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "pose").text = nums((com[0], com[1], 0.0, 0.0, 0.0, 0.0))
    ET.SubElement(inertial, "mass").text = num(mass)
    moments = ET.SubElement(inertial, "inertia")
    for key, value in (("ixx", inertia), ("ixy", 0.0), ("ixz", 0.0), ("iyy", inertia), ("iyz", 0.0), ("izz", inertia)):
        ET.SubElement(moments, key).text = num(value)


def _header(d: Drawing) -> str:
    lost = not_carried(d) + [f"the spring between {ld['between']}" for ld in d.spec.get("loads", [])
                             if ld["type"] == "spring"]
    lost += [f"the constant {ld['type']} on {ld['body']!r}" for ld in d.spec.get("loads", [])
             if ld["type"] in ("force", "torque")]
    lost += [f"the drive or motor on pair {pair!r} (SDF has no actuator element: a plugin's)" for pair, _, _ in actuated(d)]
    return header(d, "SDF", lost)


def header(d: Drawing, fmt: str, lost: list[str]) -> str:
    """The comment that opens an export: what it is, and what the format does not carry."""
    lines = [f" planardyn export of {d.name!r}; docs/exchange.md says how it maps. Planar: hinges about z,",
             f" slides in the x-y plane, every joint at 0 in the drawing. Units SI. Not carried by {fmt}:"]
    return "\n".join(lines + ([f"   - {item}" for item in lost] or ["   - nothing"])) + "\n"
