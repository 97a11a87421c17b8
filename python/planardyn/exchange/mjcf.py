"""MJCF (MuJoCo's model format): export a mechanism, import the planar subset.

Export: the spanning tree of :mod:`.tree` as nested bodies with hinges about z and slides in
the x-y plane (qpos 0 is the drawing), each closing revolute pair an equality ``connect``
between a site on each of its bodies, each gear pair an equality ``joint`` between its
shafts, springs as spatial tendons, a closing pair's spring, damper or motor on a fixed
tendon (its relative angle is the sum of the hinge angles round the loop), motors with the
gear ratio and the rotor as armature n^2 J, constant forces and torques as site actuators
with a constant bias, and the start state (and the drives' efforts at t = 0) as the keyframe
``start``. What cannot map is listed in a comment at the top of the file.

Import: ``<worldbody>`` bodies whose joints are hinges with parallel axes (along +-z after
the body rotations) and slides in the x-y plane, each body with an ``<inertial>``; equality
``connect`` between two bodies; anything else is refused, naming the element and its line.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Any

import numpy as np

from .tree import GROUND, Drawing, Edge, actuated, drawing, joint_state, not_carried, pair_loads
from .xmltext import num, nums, text
from ..mechanism import Mechanism

#: Default step (s) written in ``<option>``: MuJoCo's RK4 with loops stiffened to this step
#: keeps the shipped models within the accuracy of tests/test_exchange_mujoco.py.
TIMESTEP = 1e-3
#: The closing constraints' impedance (MuJoCo's solimp): as close to 1 as allowed, so that
#: the constraint force is barely softened (the default 0.9, 0.95 lets loops gape by mm).
SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
#: Radius of the drawn links, a fraction of the mechanism's size (visual only).
LINK_RADIUS = 0.01


def _v(p: np.ndarray) -> str:
    return nums((p[0], p[1], 0.0))


def _site(body: str, point: str) -> str:
    return f"{point}@{body}"


def to_mjcf(mech: Mechanism, timestep: float = TIMESTEP) -> str:
    """The MJCF text of a mechanism (a string; ``mujoco.MjModel.from_xml_string`` reads it).

    Parameters
    ----------
    mech : Mechanism
    timestep : float
        MuJoCo's step (s). The closing equalities get ``solref = (2 timestep, 1)``, the
        stiffest MuJoCo allows (a time constant of two steps, critically damped).

    Raises
    ------
    ExchangeError
        A loop closed by prismatic or slot pairs only, or a gear whose shaft closes a loop.
    """
    d = drawing(mech)
    root = ET.Element("mujoco", model=d.name)
    lost = not_carried(d)
    root.append(ET.Comment(_header(d, lost)))
    ET.SubElement(root, "compiler", angle="radian", inertiafromgeom="false", autolimits="true")
    ET.SubElement(root, "option", timestep=num(timestep), integrator="RK4", gravity=_v(np.asarray(mech.gravity)))
    _custom(root, d)
    world = ET.SubElement(root, "worldbody")
    joints: dict[str, ET.Element] = {}  # per pair: the element carrying its spring, damper, armature
    _sites(d, world, GROUND)
    if any(load["type"] in ("force", "torque") for load in d.spec.get("loads", [])):
        ET.SubElement(world, "site", name="world_frame")  # the frame constant loads keep their directions in
    for e in d.children(GROUND):
        _body(d, world, e, joints)
    solref = f"{num(2 * timestep)} 1"
    contact, equality, tendon, actuator = (ET.Element(t) for t in ("contact", "equality", "tendon", "actuator"))
    for p in d.closing:
        ET.SubElement(contact, "exclude", body1=_mj_body(p.a), body2=_mj_body(p.b))
        ET.SubElement(equality, "connect", name=p.name, site1=_site(p.a, p.point), site2=_site(p.b, p.point),
                      solref=solref, solimp=nums(SOLIMP))
        joints[p.name] = _closing_tendon(d, tendon, p.name, p.a, p.b)
    for c in d.couplings:
        ET.SubElement(equality, "joint", name=c.pair.name, joint1=_joint_name(c.follower, _kind(c.follower)),
                      joint2=_joint_name(c.leader, "hinge"), polycoef=nums((0.0, c.ratio, 0.0, 0.0, 0.0)),
                      solref=solref, solimp=nums(SOLIMP))
    _springs(d, tendon)
    _pair_terms(d, joints)
    ctrl = _actuators(d, actuator, joints)
    for el in (contact, equality, tendon, actuator):
        if len(el):
            root.append(el)
    _keyframe(d, root, ctrl)
    return text(root)


def _header(d: Drawing, lost: list[str]) -> str:
    lines = [f" planardyn export of {d.name!r} ({d.mech.source}); docs/exchange.md says how it maps.",
             " Planar: every hinge turns about z, every slide lies in the x-y plane; qpos = 0 is the drawing,",
             " the keyframe 'start' the start state. Units SI. Not carried by MJCF:"]
    lines += [f"   - {item}" for item in lost] or ["   - nothing"]
    return "\n".join(lines) + "\n"


def _mj_body(body: str) -> str:
    return "world" if body == GROUND else body


def _kind(e: Edge) -> str:
    return "hinge" if e.pair.kind == "revolute" else "slide"


def _joint_name(e: Edge, kind: str) -> str:
    """A slot's two joints are ``<pair>.slide`` and ``<pair>.hinge``; other pairs' joints
    take the pair's name."""
    return f"{e.pair.name}.{kind}" if e.pair.kind == "slot" else e.pair.name


def _sites(d: Drawing, el: ET.Element, body: str) -> None:
    names = d.mech.ground_points if body == GROUND else d.bodies[body].points
    for point in names:
        ET.SubElement(el, "site", name=_site(body, point), pos=_v(d.local(body, d.points[point])))


def _body(d: Drawing, parent: ET.Element, e: Edge, joints: dict[str, ET.Element]) -> None:
    b = d.bodies[e.child]
    el = ET.SubElement(parent, "body", name=b.name, pos=_v(d.origin[e.child] - d.origin[e.parent]))
    for kind in e.joints:
        axis = np.array([0.0, 0.0, e.sign]) if kind == "hinge" else e.sign * np.append(e.pair.axis, 0.0)
        j = ET.SubElement(el, "joint", name=_joint_name(e, kind), type=kind, axis=nums(axis))
        if kind == _kind(e):  # the pair's own relative coordinate: a slot's travel, else its only joint
            joints[e.pair.name] = j
    ET.SubElement(el, "inertial", pos=_v(d.local(b.name, b.com)), mass=num(b.mass),
                  diaginertia=nums((b.inertia, b.inertia, b.inertia)))
    radius = LINK_RADIUS * d.mech.scale
    drawn = [d.local(b.name, d.points[p]) for p in b.points]
    for p, q in zip(drawn, drawn[1:]):
        ET.SubElement(el, "geom", type="capsule", fromto=f"{_v(p)} {_v(q)}", size=num(radius),
                      contype="0", conaffinity="0")
    if len(drawn) == 1:
        ET.SubElement(el, "geom", type="sphere", pos=_v(drawn[0]), size=num(2 * radius), contype="0", conaffinity="0")
    _sites(d, el, b.name)
    for child in d.children(b.name):
        _body(d, el, child, joints)


def _closing_tendon(d: Drawing, tendon: ET.Element, name: str, a: str, b: str) -> ET.Element:
    """A fixed tendon whose length is phi_b - phi_a from the drawing: a closing pair's
    relative angle, for the spring, damper or motor on it."""
    fixed = ET.Element("fixed", name=name)
    for e, coef in d.rotation_path(a, b):
        ET.SubElement(fixed, "joint", joint=_joint_name(e, "hinge"), coef=num(coef))
    tendon.append(fixed)
    return fixed


def _springs(d: Drawing, tendon: ET.Element) -> None:
    for k, load in enumerate(d.spec.get("loads", [])):
        if load["type"] != "spring":
            continue
        (a, pa), (b, pb) = load["between"]
        rest = load.get("rest_length", float(np.linalg.norm(d.points[pa] - d.points[pb])))
        s = ET.SubElement(tendon, "spatial", name=f"spring{k}", stiffness=num(load["stiffness"]),
                          damping=num(load.get("damping", 0.0)), springlength=num(rest))
        ET.SubElement(s, "site", site=_site(a, pa))
        ET.SubElement(s, "site", site=_site(b, pb))


def _add(el: ET.Element, attr: str, value: float) -> None:
    el.set(attr, num(float(el.get(attr, "0")) + value))


def _pair_terms(d: Drawing, joints: dict[str, ET.Element]) -> None:
    """Torsional springs and viscous friction of pairs on their joints or closing tendons."""
    for pair, t in pair_loads(d).items():
        el = joints[pair]
        if t.get("stiffness"):
            _add(el, "stiffness", t["stiffness"])
            el.set("springref" if el.tag == "joint" else "springlength", num(t["rest"]))
        if t.get("damping"):
            _add(el, "damping", t["damping"])


def _actuators(d: Drawing, actuator: ET.Element, joints: dict[str, ET.Element]) -> list[float]:
    """Motors on the driven and actuated pairs (gear n, armature n^2 J, motor viscous
    friction c as joint damping n^2 c, Coulomb T_c as frictionloss n T_c, peak torque as the
    force range), then constant forces and torques; returns the controls at t = 0."""
    ctrl = []
    for pair, act, drive in actuated(d):
        el = joints[pair]
        n = float(act.get("gear_ratio", 1.0)) if act else 1.0
        motor = ET.SubElement(actuator, "motor", name=f"motor_{pair}", gear=num(n))
        motor.set("joint" if el.tag == "joint" else "tendon", el.get("name", ""))
        if act:
            _add(el, "armature", n * n * float(act.get("rotor_inertia", 0.0)))
            _add(el, "damping", n * n * float(act.get("viscous", 0.0)))
            _add(el, "frictionloss", n * float(act.get("coulomb", 0.0)))
            peak = (act.get("limits") or {}).get("peak_torque")
            if peak is not None:
                motor.set("forcerange", nums((-peak, peak)))
        ctrl.append(_effort_at_start(drive))
    for k, load in enumerate(d.spec.get("loads", [])):
        if load["type"] not in ("force", "torque"):
            continue
        body = load["body"]
        if load["type"] == "force":
            f = np.asarray(load["value"], dtype=float)
            size, site = float(np.linalg.norm(f)), _site(body, load["at"])
            gear = (f[0], f[1], 0.0, 0.0, 0.0, 0.0) / np.maximum(size, 1e-300)
        else:
            size, site = abs(float(load["value"])), _site(body, d.bodies[body].points[0])
            gear = (0.0, 0.0, 0.0, 0.0, 0.0, float(np.sign(load["value"])))
        ET.SubElement(actuator, "general", name=f"load{k}", site=site, refsite="world_frame", gear=nums(gear),
                      gainprm="0", biastype="affine", biasprm=nums((size, 0.0, 0.0)))
        ctrl.append(0.0)
    return ctrl


def _effort_at_start(drive: dict[str, Any] | None) -> float:
    if drive is None or "motion" in drive:
        return 0.0
    return float(drive["effort"]) if "effort" in drive else float(drive["table"]["effort"][0])


def _custom(root: ET.Element, d: Drawing) -> None:
    """The coordinates (name, pair, drawn value), for planardyn's importer to give back."""
    custom = ET.SubElement(root, "custom")
    for c in d.spec["coordinates"]:
        ET.SubElement(custom, "text", name=f"planardyn.coordinate.{c['name']}", data=f"{c['pair']} {num(c['value'])}")


def _keyframe(d: Drawing, root: ET.Element, ctrl: list[float]) -> None:
    qpos, qvel = joint_state(d, d.mech.q0, d.mech.qd0)
    order = [(e.pair.name, kind) for e in d.edges for kind in e.joints]
    key = ET.SubElement(ET.SubElement(root, "keyframe"), "key", name="start",
                        qpos=nums(qpos[k] for k in order), qvel=nums(qvel[k] for k in order))
    if ctrl:
        key.set("ctrl", nums(ctrl))
