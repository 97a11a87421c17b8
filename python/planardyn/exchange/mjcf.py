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
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..arguments import positive
from ..mechanism import Mechanism
from .planar import SAME_POINT, Builder
from .tree import GROUND, Drawing, Edge, Vec, actuated, drawing, joint_state, not_carried, pair_loads
from .xmltext import Document, num, nums, parse, text

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
    ArgumentError
        A timestep that is not a finite number > 0.
    ExchangeError
        A loop closed by prismatic or slot pairs only, or a gear whose shaft closes a loop.
    """
    timestep = positive("timestep", timestep, "s")
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
        j = ET.SubElement(el, "joint", name=_joint_name(e, kind), type=kind, axis=nums(e.axis(kind)))
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


# ------------------------------------------------------------------ import

#: A hinge axis counts as z, a slide axis as lying in the plane, when its off-plane (or
#: in-plane) part is below this fraction of its length (axes are written to ~1e-16).
AXIS_TOL = 1e-9
#: Elements of a body that carry no mechanics and are skipped.
IGNORED = {"geom", "camera", "light"}


@dataclass
class _Reader:
    """Reads one MJCF document into a Builder (the rules in the module docstring)."""

    doc: Document
    out: Builder
    degrees: bool
    eulerseq: str
    defaults: dict[str, dict[str, dict[str, str]]] = field(default_factory=dict)  # class -> tag -> attributes
    sites: dict[str, tuple[str, Vec]] = field(default_factory=dict)  # MJCF site -> (body, world xy)
    frames: dict[str, tuple[str, Vec, np.ndarray]] = field(default_factory=dict)  # MJCF body -> (pd body, p, R)
    joints: list[tuple[str, str, str]] = field(default_factory=list)  # (MJCF joint, pair, 'hinge' | 'slide')
    armature: dict[str, tuple[float, float]] = field(default_factory=dict)  # pair -> (armature, frictionloss)
    tendons: dict[str, list[tuple[str, float]]] = field(default_factory=dict)  # closing pair -> (joint, coef)

    # -------------------------------------------------------------- attributes

    def attrs(self, el: ET.Element, cls: str) -> dict[str, str]:
        """The element's attributes over those of its default class."""
        return {**self.defaults.get(el.get("class", cls), {}).get(el.tag, {}), **el.attrib}

    def read_defaults(self, el: ET.Element, inherited: dict[str, dict[str, str]], name: str = "main") -> None:
        own: dict[str, dict[str, str]] = {tag: dict(attrs) for tag, attrs in inherited.items()}
        for child in el:
            if child.tag == "default":
                continue
            own[child.tag] = {**own.get(child.tag, {}), **child.attrib}
        self.defaults[name] = own
        for child in el.findall("default"):
            self.read_defaults(child, own, child.get("class", name))

    def rotation(self, el: ET.Element) -> np.ndarray:
        """The 3x3 rotation of a body or inertial frame relative to its parent."""
        from scipy.spatial.transform import Rotation

        unit = np.pi / 180.0 if self.degrees else 1.0
        if el.get("quat") is not None:
            w, x, y, z = self.doc.floats(el, "quat", 4)
            return Rotation.from_quat([x, y, z, w]).as_matrix()
        if el.get("axisangle") is not None:
            x, y, z, a = self.doc.floats(el, "axisangle", 4)
            return Rotation.from_rotvec(np.array([x, y, z]) / np.linalg.norm([x, y, z]) * a * unit).as_matrix()
        if el.get("euler") is not None:
            # MJCF: lower case turns about the moving axes; scipy's lower case is the fixed ones.
            return Rotation.from_euler(self.eulerseq.swapcase(), np.array(self.doc.floats(el, "euler", 3)) * unit).as_matrix()
        if el.get("xyaxes") is not None or el.get("zaxis") is not None:
            raise self.doc.error(el, "xyaxes and zaxis orientations are not read: give quat, axisangle or euler")
        return np.eye(3)

    # -------------------------------------------------------------- the tree

    def body(self, el: ET.Element, parent: str, p0: Vec, r0: np.ndarray, cls: str) -> None:
        """An MJCF body: a new planardyn body if it has joints, else part of its parent's."""
        cls = el.get("childclass", cls)
        p = p0 + r0 @ np.array(self.doc.floats(el, "pos", 3, "0 0 0"))
        r = r0 @ self.rotation(el)
        joints = [c for c in el if c.tag in ("joint", "freejoint")]
        name = el.get("name") or f"body{len(self.frames)}"
        owner = name if joints else parent
        self.frames[name] = (owner, p, r)
        for child in el:
            if child.tag == "inertial":
                self.inertial(child, owner, p, r)
            elif child.tag == "site":
                xy = (p + r @ np.array(self.doc.floats(child, "pos", 3, "0 0 0")))[:2]
                site = child.get("name") or f"site{len(self.sites)}"
                self.sites[site] = (owner, xy)
                self.out.point(owner, site.split("@")[0], xy)
        if joints:
            if not self.out.parts.get(owner):
                raise self.doc.error(el, "a moving body needs an <inertial> (planardyn does not derive mass from geoms)")
            self.pair(el, joints, parent, owner, p, r, cls)
        for child in el:
            if child.tag == "body":
                self.body(child, owner, p, r, cls)
            elif child.tag not in IGNORED | {"inertial", "site", "joint"}:
                raise self.doc.error(child, "not part of the planar subset planardyn reads "
                                            "(bodies, hinge and slide joints, inertials, sites, geoms)")

    def inertial(self, el: ET.Element, owner: str, p: Vec, r: np.ndarray) -> None:
        rot = r @ self.rotation(el)
        if el.get("fullinertia") is not None:
            ixx, iyy, izz, ixy, ixz, iyz = self.doc.floats(el, "fullinertia", 6)
            inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        else:
            inertia = np.diag(self.doc.floats(el, "diaginertia", 3))
        com = (p + r @ np.array(self.doc.floats(el, "pos", 3)))[:2]
        self.out.part(owner, self.doc.floats(el, "mass", 1)[0], float((rot @ inertia @ rot.T)[2, 2]), com)


    def pair(self, el: ET.Element, joints: list[ET.Element], parent: str, child: str, p: Vec, r: np.ndarray,
             cls: str) -> None:
        """The pair of a body's joints: a hinge, a slide, or a slot (a slide and a hinge)."""
        found = []
        for j in joints:
            a = self.attrs(j, cls)
            kind = "free" if j.tag == "freejoint" else a.get("type", "hinge")
            if kind not in ("hinge", "slide"):
                raise self.doc.error(j, f"a {kind} joint is not planar: planardyn reads hinges about z and slides in the x-y plane")
            axis = r @ np.array(self.doc.floats(j, "axis", 3, a.get("axis", "0 0 1")))
            axis /= np.linalg.norm(axis)
            anchor = (p + r @ np.array([float(v) for v in a.get("pos", "0 0 0").split()]))[:2]
            off = np.linalg.norm(axis[:2]) if kind == "hinge" else abs(axis[2])
            if off > AXIS_TOL:
                what = "turn about the z axis" if kind == "hinge" else "lie in the x-y plane"
                raise self.doc.error(j, f"its axis {axis.round(12).tolist()} does not {what} (planar subset)")
            found.append((j, a, kind, axis, anchor))
        kinds = tuple(f[2] for f in found)
        name = (found[0][0].get("name") or f"joint{len(self.joints)}").split(".")[0]
        if kinds == ("hinge",):
            j, a, _, axis, at = found[0]
            bodies = [parent, child] if axis[2] > 0 else [child, parent]
            self.out.pair("revolute", name, bodies[0], bodies[1], self.out.share(parent, self.out.point(child, name, at)))
        elif kinds == ("slide",):
            j, a, _, axis, at = found[0]
            self.out.pair("prismatic", name, parent, child, self.out.point(child, name, at), axis)
        elif kinds in (("slide", "hinge"), ("hinge", "slide")):
            slide, hinge = (found[0], found[1]) if kinds[0] == "slide" else (found[1], found[0])
            at = hinge[4]
            if kinds[0] == "slide":  # the slot on the parent, the pin on the child
                self.out.pair("slot", name, parent, child, self.out.point(child, name, at), slide[3])
            else:  # the slot on the child, turning about the parent's pin
                self.out.pair("slot", name, child, parent, self.out.point(parent, name, at), -slide[3])
        else:
            raise self.doc.error(el, f"joints {list(kinds)}: planardyn reads one hinge, one slide, or a slide and a hinge "
                                     "(a slot) per body; put a massive body between the others")
        for j, a, kind, _, _ in found:
            self.joints.append((j.get("name", ""), name, kind))
            if len(found) == 1 or kind == "slide":  # a slot's coordinate is its travel; its hinge turns freely
                self.joint_terms(a, name, kind)
            elif any(float(a.get(key, 0.0)) for key in ("stiffness", "damping", "armature", "frictionloss")):
                raise self.doc.error(j, "a slot's hinge turns freely in planardyn: no stiffness, damping or armature")

    def joint_terms(self, a: dict[str, str], pair: str, kind: str) -> None:
        """Joint stiffness and damping as the pair's torsional spring and viscous friction
        (on a slot's slide only: its hinge is free)."""
        unit = np.pi / 180.0 if self.degrees and kind == "hinge" else 1.0
        k, c = float(a.get("stiffness", 0.0)), float(a.get("damping", 0.0))
        if k:
            self.out.loads.append({"type": "torsional_spring", "pair": pair, "stiffness": k,
                                   "rest": float(a.get("springref", 0.0)) * unit})
        if c:
            self.out.loads.append({"type": "friction", "pair": pair, "viscous": c})
        if float(a.get("armature", 0.0)) or float(a.get("frictionloss", 0.0)):
            self.armature[pair] = (float(a.get("armature", 0.0)), float(a.get("frictionloss", 0.0)))

    # -------------------------------------------------------------- after the tree

    def site(self, el: ET.Element, attr: str) -> tuple[str, Vec]:
        name = el.get(attr, "")
        if name not in self.sites:
            raise self.doc.error(el, f"{attr}={name!r} is not a site of the model")
        return self.sites[name]

    def equality(self, el: ET.Element, scale: float) -> None:
        """A ``connect`` between two bodies: a closing revolute pair."""
        for k, eq in enumerate(el):
            name = eq.get("name") or f"{eq.tag}{k}"
            if eq.tag == "joint":
                self.gear(eq, name)
                continue
            if eq.tag != "connect":
                raise self.doc.error(eq, "only equality connect (a closing revolute pair) and joint (a gear pair) are "
                                         "read: weld, tendon and distance equalities are not in the planar subset")
            if eq.get("site1") is not None:
                (b1, p1), (b2, p2) = self.site(eq, "site1"), self.site(eq, "site2")
                hint = eq.get("site1", "").split("@")[0]
            else:
                f1, f2 = (self.frames.get(eq.get(key, ""), None) for key in ("body1", "body2"))
                if f1 is None or f2 is None:
                    raise self.doc.error(eq, "body1 and body2 must name bodies of the model")
                b1, b2 = f1[0], f2[0]
                p1 = p2 = (f1[1] + f1[2] @ np.array(self.doc.floats(eq, "anchor", 3)))[:2]
                hint = name
            if np.linalg.norm(p1 - p2) > SAME_POINT * scale:
                raise self.doc.error(eq, f"its two points are {np.linalg.norm(p1 - p2):.3g} m apart in the reference "
                                         "configuration: planardyn's drawing must be assembled")
            self.out.pair("revolute", name, b1, b2, self.out.share(b2, self.out.point(b1, hint, p1)))

    def gear(self, eq: ET.Element, name: str) -> None:
        """An equality ``joint`` q1 = c1 q2 between two joints on one carrier: a gear pair."""
        coef = self.doc.floats(eq, "polycoef", 5, "0 1 0 0 0")
        if coef[0] or any(coef[2:]) or not coef[1]:
            raise self.doc.error(eq, "a gear couples two joints linearly: polycoef must be '0 ratio 0 0 0'")
        joint = {jn: pr for jn, pr, _ in self.joints}
        if eq.get("joint1") not in joint or eq.get("joint2") not in joint:
            raise self.doc.error(eq, "joint1 and joint2 must name joints of the model")
        why = self.out.gear(name, joint[eq.get("joint1", "")], joint[eq.get("joint2", "")], coef[1])
        if why:
            raise self.doc.error(eq, why)

    def tendon(self, el: ET.Element) -> None:
        """Spatial tendons between two sites (springs) and planardyn's closing-pair tendons."""
        pairs = {p["name"] for p in self.out.pairs}
        for t in el:
            k, c = float(t.get("stiffness", 0.0)), float(t.get("damping", 0.0))
            if t.tag == "spatial" and len(t) == 2 and all(s.tag == "site" for s in t):
                (b1, p1), (b2, p2) = (self.site(s, "site") for s in t)
                ends = [[b, self.out.point(b, s.get("site", ""), p)] for (b, p), s in zip(((b1, p1), (b2, p2)), t)]
                spring: dict[str, Any] = {"type": "spring", "between": ends, "stiffness": k, "damping": c}
                if t.get("springlength") is not None:
                    spring["rest_length"] = self.doc.floats(t, "springlength", 1)[0]
                self.out.loads.append(spring)
            elif t.tag == "fixed" and t.get("name") in pairs:
                self.tendons[t.get("name", "")] = [(j.get("joint", ""), float(j.get("coef", 1.0))) for j in t]
                self.joint_terms({key: t.get(key, "0") for key in ("stiffness", "damping", "armature", "frictionloss")}
                                 | {"springref": t.get("springlength", "0")}, t.get("name", ""), "slide")
            else:
                raise self.doc.error(t, "only spatial tendons between two sites (springs) and fixed tendons named "
                                        "after a closing connect are read")

    def actuators(self, el: ET.Element | None, ctrl: list[float]) -> list[tuple[str, float, float]]:
        """Motors as (pair, gear, control at the start); constant site forces and torques as loads."""
        motors = []
        for k, act in enumerate(el if el is not None else []):
            target = act.get("joint") or act.get("tendon")
            if act.tag == "motor" and target:
                pair = next((pr for jn, pr, _ in self.joints if jn == target), target)
                motors.append((pair, float(act.get("gear", "1").split()[0]), ctrl[k] if k < len(ctrl) else 0.0))
            elif act.tag == "general" and act.get("site") and act.get("refsite") and float(act.get("gainprm", "1").split()[0]) == 0.0:
                body, at = self.site(act, "site")
                bias = float(act.get("biasprm", "0").split()[0])
                gear = np.array(self.doc.floats(act, "gear", 6))
                if gear[3] or gear[4] or gear[2]:
                    raise self.doc.error(act, "a constant load out of the plane")
                if gear[5]:
                    self.out.loads.append({"type": "torque", "body": body, "value": float(gear[5] * bias)})
                else:
                    point = self.out.point(body, act.get("site", ""), at)
                    self.out.loads.append({"type": "force", "body": body, "at": point, "value": (gear[:2] * bias).tolist()})
            else:
                raise self.doc.error(act, "only motors on joints or closing tendons, and constant site loads, are read")
        return motors


def from_mjcf(data: str, source: str = "<string>") -> dict[str, Any]:
    """A planardyn model dict from MJCF text (the planar subset; ``planardyn.from_dict`` builds it).

    Raises
    ------
    ExchangeError
        An element outside the planar subset, named with its line.
    """
    doc = parse(data, source)
    if doc.root.tag != "mujoco":
        raise doc.error(doc.root, "not an MJCF file: the root element must be <mujoco>")
    compiler = doc.root.find("compiler")
    attrs = compiler.attrib if compiler is not None else {}
    if attrs.get("coordinate", "local") != "local" or attrs.get("inertiafromgeom") == "true":
        raise doc.error(compiler, "global coordinates and inertia from geoms are not read")  # type: ignore[arg-type]
    out = Builder(doc.root.get("model", "imported"), source)
    r = _Reader(doc, out, attrs.get("angle", "degree") == "degree", attrs.get("eulerseq", "xyz"))
    for el in doc.root.findall("default"):
        r.read_defaults(el, {})
    option = doc.root.find("option")
    out.gravity = np.array(doc.floats(option, "gravity", 3, "0 0 -9.81") if option is not None else [0, 0, -9.81])[:2]
    world = doc.root.find("worldbody")
    if world is None:
        raise doc.error(doc.root, "no <worldbody>")
    r.frames["world"] = (GROUND, np.zeros(3), np.eye(3))
    for child in world:
        if child.tag == "site":
            xy = np.array(doc.floats(child, "pos", 3, "0 0 0"))[:2]
            site = child.get("name") or f"site{len(r.sites)}"
            r.sites[site] = (GROUND, xy)
            out.point(GROUND, site.split("@")[0], xy)
        elif child.tag == "body":
            r.body(child, GROUND, np.zeros(3), np.eye(3), "main")
        elif child.tag not in IGNORED:
            raise doc.error(child, "not part of the planar subset planardyn reads")
    out.masses(source)
    scale = max([1.0] + [float(np.max(np.abs(p))) for p in out.points.values()])
    for tag, read in (("equality", lambda el: r.equality(el, scale)), ("tendon", r.tendon)):
        for el in doc.root.findall(tag):
            read(el)
    key = doc.root.find("keyframe/key")
    ctrl = doc.floats(key, "ctrl", len(key.get("ctrl", "").split())) if key is not None and key.get("ctrl") else []
    motors = r.actuators(doc.root.find("actuator"), ctrl)
    _coordinates(doc, r, motors, key)
    return out.model()


def _coordinates(doc: Document, r: _Reader, motors: list[tuple[str, float, float]], key: ET.Element | None) -> None:
    """The coordinates (planardyn's own list in <custom>, else chosen), their start state
    from the keyframe, and the motors as drives and actuators."""
    out = r.out
    for text_el in doc.root.iterfind("custom/text"):
        name = text_el.get("name", "")
        if name.startswith("planardyn.coordinate."):
            pair, value = text_el.get("data", "").split()
            out.coordinates.append({"name": name.removeprefix("planardyn.coordinate."), "pair": pair, "value": float(value)})
    out.preferred = [m[0] for m in motors]
    out.choose_coordinates()
    if key is not None:
        zeros = " ".join(["0"] * len(r.joints))
        qpos, qvel = (doc.floats(key, attr, len(r.joints), zeros) for attr in ("qpos", "qvel"))
        by_joint = {jn: k for k, (jn, _, _) in enumerate(r.joints)}
        kinds = {p["name"]: p["type"] for p in out.pairs}
        for c in out.coordinates:
            own = "hinge" if kinds[c["pair"]] == "revolute" else "slide"
            terms = r.tendons.get(c["pair"]) or [(jn, 1.0) for jn, pr, kind in r.joints if pr == c["pair"] and kind == own]
            q = sum(coef * qpos[by_joint[jn]] for jn, coef in terms)
            qd = sum(coef * qvel[by_joint[jn]] for jn, coef in terms)
            if q:
                c["q0"] = c["value"] + q
            if qd:
                c["qd0"] = qd
    coord_of = {c["pair"]: c["name"] for c in out.coordinates}
    for pair, gear, effort in motors:
        armature, friction = r.armature.pop(pair, (0.0, 0.0))
        where = {"coordinate": coord_of[pair]} if pair in coord_of else {"pair": pair}
        if gear != 1.0 or armature or friction:
            out.actuators.append({**where, "gear_ratio": gear, "rotor_inertia": armature / gear**2,
                                  "coulomb": friction / gear})
        if effort and pair in coord_of:
            out.drives.append({"coordinate": coord_of[pair], "effort": effort})
    for pair, (armature, friction) in r.armature.items():
        if pair not in coord_of:
            raise doc.error(doc.root, f"joint armature or frictionloss on {pair!r}, which is not a coordinate: "
                                      "planardyn carries rotor inertia and motor friction on actuated coordinates")
        out.actuators.append({"coordinate": coord_of[pair], "rotor_inertia": armature, "coulomb": friction})
