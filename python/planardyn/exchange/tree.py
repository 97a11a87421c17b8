"""A mechanism as the robot-description formats see it: the drawing, a spanning tree of its
pairs, the pairs that close its loops, and the gear pairs as couplings of tree joints.

MJCF and URDF describe a kinematic tree (SDF a graph, but simulators still integrate a tree
and close the rest by constraints), so the exporters share one choice of tree. It is grown
by Kruskal's rule over the pairs in this order of preference:

1. prismatic and slot pairs: a closing one has no equality constraint in MJCF (``connect`` is
   a point coincidence, ``weld`` a full weld);
2. the revolute shafts of gears: a gear pair becomes a linear relation between two joints
   (MJCF ``joint`` equality, URDF and SDF ``mimic``), which needs both shafts in the tree;
3. the coordinates' pairs: actuators and springs act on joints;
4. every other revolute pair, in the file's order.

The revolute pairs left out close the loops, each a point coincidence (MJCF ``connect``, a
``revolute`` joint in SDF and in URDF's ``<gazebo>`` block). Every tree joint is oriented so
that its position is the pair's relative motion of b to a from the drawing, whichever of a
and b the tree makes the parent: a hinge turns about +z or -z, a slide along +axis or -axis.

Body frames sit at the point of the body's tree pair (the pin, the slider's point), with the
axes of the drawing; the centre of mass, the points and the inertia are given in that frame.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._core import PlanardynError
from ..mechanism import Mechanism

Vec = NDArray[np.float64]

GROUND = "ground"

#: Tree preference of each pair kind (lower first), after the gear shafts and coordinates.
KIND_ORDER = {"prismatic": 0, "slot": 0, "revolute": 3}


class ExchangeError(PlanardynError, ValueError):
    """A mechanism or a file that a format cannot carry; the message says what and why."""


@dataclass(frozen=True)
class Body:
    """A mobile body: mass (kg), moment of inertia about its centre of mass (kg m^2), the
    drawn centre of mass (m) and angle (rad), and the names of the points it carries."""

    name: str
    mass: float
    inertia: float
    com: Vec
    phi: float
    points: tuple[str, ...]


@dataclass(frozen=True)
class Pair:
    """A pair: ``kind`` revolute, prismatic, slot or gear; b moves relative to a; ``point``
    its point (a gear's first centre); ``axis`` the unit guide or slot direction in the
    drawing (prismatic, slot); ``spec`` the model file's entry (a gear's fields)."""

    name: str
    kind: str
    a: str
    b: str
    point: str
    axis: Vec | None
    spec: dict[str, Any]


@dataclass(frozen=True)
class Edge:
    """A pair of the tree, oriented from the parent body to the child."""

    pair: Pair
    parent: str
    child: str

    @property
    def sign(self) -> float:
        """+1 when the parent is the pair's body a, -1 when the tree turns the pair around."""
        return 1.0 if self.parent == self.pair.a else -1.0

    @property
    def joints(self) -> tuple[str, ...]:
        """The one-axis joints of the edge, parent side first: a slot is a slide along the
        slot (fixed in a) and a hinge at the pin, in the order the tree meets them."""
        if self.pair.kind == "slot":
            return ("slide", "hinge") if self.sign > 0 else ("hinge", "slide")
        return ("hinge",) if self.pair.kind == "revolute" else ("slide",)


    def axis(self, kind: str) -> Vec:
        """(3,) the axis of the edge's hinge (+-z) or slide (+-guide), oriented so that the
        joint's position is the pair's relative motion of b to a."""
        if kind == "hinge":
            return np.array([0.0, 0.0, self.sign])
        assert self.pair.axis is not None  # a prismatic or slot pair has a guide
        return self.sign * np.append(self.pair.axis, 0.0)


@dataclass(frozen=True)
class Coupling:
    """A gear pair as a relation of two tree joints: q_follower = ratio q_leader, both
    joint positions from the drawing (rad, or m for a rack's guide)."""

    pair: Pair
    follower: Edge
    leader: Edge
    ratio: float


@dataclass(frozen=True)
class Drawing:
    """The mechanism as drawn, its spanning tree (``edges``, depth first), the closing pairs
    and the gear couplings; ``origin`` is each body's frame origin in the drawing (m)."""

    mech: Mechanism
    spec: dict[str, Any]
    points: dict[str, Vec]
    bodies: dict[str, Body]
    pairs: dict[str, Pair]
    edges: tuple[Edge, ...]
    closing: tuple[Pair, ...]
    couplings: tuple[Coupling, ...]
    origin: dict[str, Vec]

    @property
    def name(self) -> str:
        return str(self.spec["name"])

    def edge(self, pair: str) -> Edge | None:
        """The tree edge of a pair, or None for a closing pair or a gear."""
        return next((e for e in self.edges if e.pair.name == pair), None)

    def children(self, body: str) -> list[Edge]:
        return [e for e in self.edges if e.parent == body]

    def local(self, body: str, p: Vec) -> Vec:
        """(2,) a drawn position in the body's frame (m)."""
        return p - self.origin[body]

    def rotation_path(self, a: str, b: str) -> list[tuple[Edge, float]]:
        """The hinges whose positions sum to phi_b - phi_a (from the drawing), with their
        coefficients: in the plane every body angle is the sum of the hinge angles on its
        tree path from ground."""
        terms: dict[str, tuple[Edge, float]] = {}
        for body, side in ((b, 1.0), (a, -1.0)):
            for e in self._up(body):
                if "hinge" in e.joints:  # the child turns by sign * (the hinge's position) from its parent
                    terms[e.pair.name] = (e, terms.get(e.pair.name, (e, 0.0))[1] + side * e.sign)
        return [(e, c) for e, c in terms.values() if c != 0.0]

    def _up(self, body: str) -> Iterable[Edge]:
        while body != GROUND:
            e = next(e for e in self.edges if e.child == body)
            yield e
            body = e.parent


def drawing(mech: Mechanism) -> Drawing:
    """The drawing of a mechanism and its spanning tree (the rules in the module docstring).

    Raises
    ------
    ExchangeError
        A prismatic or slot pair closes a loop of such pairs only, or a gear's shaft is not
        a tree joint: no equality of the formats expresses it.
    """
    spec = mech.to_dict()
    x0 = np.asarray(mech.x0, dtype=float).reshape(-1, 3)
    points = {n: np.asarray(p, dtype=float) for n, p in zip(mech.point_names, mech.point_positions(mech.x0))}
    bodies = {
        name: Body(name, float(m), float(i), x0[k, :2].copy(), float(x0[k, 2]), tuple(p for p, _ in bp))
        for k, (name, m, i, bp) in enumerate(zip(mech.body_names, mech.masses, mech.inertias, mech.body_points))
    }
    phi = {GROUND: 0.0} | {b.name: b.phi for b in bodies.values()}
    pairs = {}
    for native, entry in zip(mech.pairs, spec["pairs"]):
        a, b = native["bodies"]
        axis = native.get("axis")
        if axis is not None:
            c, s = np.cos(phi[a]), np.sin(phi[a])
            axis = np.array([c * axis[0] - s * axis[1], s * axis[0] + c * axis[1]])
        pairs[native["name"]] = Pair(native["name"], native["kind"], a, b, native["point"], axis, entry)
    edges = _tree(mech, spec, list(pairs.values()), set(bodies))
    origin = {GROUND: np.zeros(2)} | {e.child: points[e.pair.point] for e in edges}
    in_tree = {e.pair.name for e in edges}
    closing = tuple(p for p in pairs.values() if p.kind != "gear" and p.name not in in_tree)
    for p in closing:
        if p.kind != "revolute":
            raise ExchangeError(
                f"{mech.source}: the {p.kind} pair {p.name!r} closes a loop of prismatic and slot pairs only; "
                "the formats close loops by point coincidence (a revolute pair): put a revolute pair in that loop")
    d = Drawing(mech, spec, points, bodies, pairs, edges, closing, (), origin)
    couplings = tuple(_coupling(d, p) for p in pairs.values() if p.kind == "gear")
    return Drawing(mech, spec, points, bodies, pairs, edges, closing, couplings, origin)


def _shafts(spec: dict[str, Any], pairs: list[Pair]) -> set[str]:
    """The revolute pairs (and a rack's guide) holding gears to their carriers."""
    shafts = set()
    for g in (p for p in pairs if p.kind == "gear"):
        carrier = g.spec.get("carrier", GROUND)
        for body, center in zip((g.a, g.b), g.spec["centers"]):
            shafts |= {p.name for p in pairs if p.kind == "revolute" and {p.a, p.b} == {body, carrier} and p.point == center}
        if g.spec.get("rack"):
            shafts |= {p.name for p in pairs if p.kind == "prismatic" and {p.a, p.b} == {g.b, carrier}}
    return shafts


def _tree(mech: Mechanism, spec: dict[str, Any], pairs: list[Pair], bodies: set[str]) -> tuple[Edge, ...]:
    """Kruskal's spanning tree over the preferred order, then oriented depth first from ground."""
    shafts = _shafts(spec, pairs)
    coords = {c["pair"] for c in spec["coordinates"]}

    def rank(p: Pair) -> int:
        return KIND_ORDER[p.kind] if p.kind != "revolute" else 1 if p.name in shafts else 2 if p.name in coords else 3

    parent = {b: b for b in bodies | {GROUND}}

    def root(b: str) -> str:
        while parent[b] != b:
            b = parent[b]
        return b

    chosen = []
    for p in sorted((p for p in pairs if p.kind != "gear"), key=rank):  # sorted() is stable: file order within a rank
        ra, rb = root(p.a), root(p.b)
        if ra != rb:
            parent[ra] = rb
            chosen.append(p)
    edges: list[Edge] = []

    def visit(body: str) -> None:
        for p in chosen:
            if body in (p.a, p.b) and all(e.pair is not p for e in edges):
                e = Edge(p, body, p.b if p.a == body else p.a)
                edges.append(e)
                visit(e.child)

    visit(GROUND)
    if len(edges) != len(bodies):  # the loader refuses such a model; kept for a clear message
        placed = {e.child for e in edges}
        raise ExchangeError(f"{mech.source}: bodies {sorted(bodies - placed)} are not connected to ground")
    return tuple(edges)


def _coupling(d: Drawing, g: Pair) -> Coupling:
    """A gear pair's row (docs/model-format.md, Gear pairs) as q_follower = ratio q_leader of
    the two shafts' tree joints (each joint's position: its pair's relative motion)."""
    carrier = g.spec.get("carrier", GROUND)

    def shaft(body: str, kind: str, center: str | None) -> tuple[Edge, float]:
        for e in d.edges:
            p = e.pair
            if p.kind == kind and {p.a, p.b} == {body, carrier} and (center is None or p.point == center):
                return e, 1.0 if p.a == carrier else -1.0  # the gear's motion relative to the carrier per unit position
        raise ExchangeError(
            f"{d.mech.source}: gear pair {g.name!r}: the {kind} pair holding {body!r} to {carrier!r} is not a joint "
            "of the spanning tree, and the formats couple tree joints only")

    r_a = float(g.spec["radii"][0])
    lead, s_a = shaft(g.a, "revolute", g.spec["centers"][0])
    if g.spec.get("rack"):
        guide, s_g = shaft(g.b, "prismatic", None)
        p, q = (d.points[n] for n in g.spec["rack"])
        e = (q - p) / np.linalg.norm(q - p)
        toward_q = float(np.sign(e @ guide.pair.axis))  # the guide's axis along P -> Q or against it
        r = p - d.points[g.spec["centers"][0]]
        sigma = 1.0 if e[0] * r[1] - e[1] * r[0] < 0 else -1.0  # rack on the pinion's right looking along P -> Q
        return Coupling(g, guide, lead, sigma * r_a * s_a * toward_q * s_g)
    r_b = float(g.spec["radii"][1]) * (-1.0 if g.spec.get("internal") else 1.0)
    follow, s_b = shaft(g.b, "revolute", g.spec["centers"][1])
    return Coupling(g, follow, lead, -s_a * s_b * r_a / r_b)


# ------------------------------------------------------------------ the state of the tree joints


def carried(d: Drawing, body: str, p: Vec, x: Vec) -> Vec:
    """(2,) where the drawn point p (m) is when the bodies are at x (3n,), carried by ``body``."""
    if body == GROUND:
        return p
    k = d.mech.body_names.index(body)
    b = d.bodies[body]
    turn = x[3 * k + 2] - b.phi
    c, s = np.cos(turn), np.sin(turn)
    r = p - b.com
    return x[3 * k: 3 * k + 2] + np.array([c * r[0] - s * r[1], s * r[0] + c * r[1]])


def _velocity(d: Drawing, body: str, at: Vec, x: Vec, xd: Vec) -> Vec:
    """(2,) velocity (m/s) of the body's material point now at ``at`` (m)."""
    if body == GROUND:
        return np.zeros(2)
    k = d.mech.body_names.index(body)
    r = at - x[3 * k: 3 * k + 2]
    return xd[3 * k: 3 * k + 2] + xd[3 * k + 2] * np.array([-r[1], r[0]])


def joint_state(d: Drawing, q: Vec, qd: Vec) -> tuple[dict[tuple[str, str], float], dict[tuple[str, str], float]]:
    """Positions and rates of the tree joints, keyed (pair name, 'hinge' | 'slide'), at the
    coordinates q and rates qd: a hinge's is the pair's relative turn from the drawing (rad,
    rad/s), a slide's the travel of b's point along the guide fixed in a (m, m/s)."""
    kin = d.mech.kinematics(q, qd)
    x, xd = np.asarray(kin["x"]), np.asarray(kin["xd"])
    angle = {GROUND: (0.0, 0.0)} | {n: (x[3 * k + 2] - d.bodies[n].phi, xd[3 * k + 2])
                                    for k, n in enumerate(d.mech.body_names)}
    qpos, qvel = {}, {}
    for e in d.edges:
        p = e.pair
        if "hinge" in e.joints:
            qpos[p.name, "hinge"] = angle[p.b][0] - angle[p.a][0]
            qvel[p.name, "hinge"] = angle[p.b][1] - angle[p.a][1]
        if "slide" in e.joints:
            assert p.axis is not None  # a prismatic or slot pair has a guide
            turn = angle[p.a][0]
            axis = np.array([np.cos(turn) * p.axis[0] - np.sin(turn) * p.axis[1],
                             np.sin(turn) * p.axis[0] + np.cos(turn) * p.axis[1]])
            drawn = d.points[p.point]
            pin, guide = carried(d, p.b, drawn, x), carried(d, p.a, drawn, x)
            qpos[p.name, "slide"] = float(axis @ (pin - guide))
            # d/dt of axis . (pin - guide): the axis turns at right angles to itself and
            # pin - guide lies along it, so only the relative velocity of the two copies counts.
            qvel[p.name, "slide"] = float(axis @ (_velocity(d, p.b, pin, x, xd) - _velocity(d, p.a, pin, x, xd)))
    return qpos, qvel


# ------------------------------------------------------------------ loads and what no format carries


def pair_loads(d: Drawing) -> dict[str, dict[str, float]]:
    """Per pair name, its linear terms: ``stiffness`` (N m/rad or N/m), ``rest`` (rad or m
    from the drawing), ``damping`` (N m s/rad or N s/m, the torsional spring's and the
    pair's viscous friction added)."""
    terms: dict[str, dict[str, float]] = {}
    for load in d.spec.get("loads", []):
        if load["type"] == "torsional_spring":
            t = terms.setdefault(load["pair"], {})
            t["stiffness"] = t.get("stiffness", 0.0) + float(load["stiffness"])
            t["rest"] = float(load.get("rest", 0.0))
            t["damping"] = t.get("damping", 0.0) + float(load.get("damping", 0.0))
        elif load["type"] == "friction" and load.get("viscous"):
            t = terms.setdefault(load["pair"], {})
            t["damping"] = t.get("damping", 0.0) + float(load["viscous"])
    return terms


def actuated(d: Drawing) -> list[tuple[str, dict[str, Any] | None, dict[str, Any] | None]]:
    """(pair name, the model file's actuator or None, the drive or None) of every coordinate
    with a drive or an actuator, then every pair actuator: what the formats' motors act on."""
    by_coord = {a["coordinate"]: a for a in d.spec.get("actuators", []) if a.get("coordinate")}
    drives = {dr["coordinate"]: dr for dr in d.spec.get("drives", [])}
    out = [(c["pair"], by_coord.get(c["name"]), drives.get(c["name"]))
           for c in d.spec["coordinates"] if c["name"] in by_coord or c["name"] in drives]
    out += [(a["pair"], a, None) for a in d.spec.get("actuators", []) if a.get("pair")]
    return out


def not_carried(d: Drawing) -> list[str]:
    """What of the model no exchange format carries, one sentence each (docs/exchange.md)."""
    lost = []
    for load in d.spec.get("loads", []):
        if load["type"] == "friction" and load.get("mu"):
            lost.append(f"Coulomb friction at pair {load['pair']!r} (mu = {load['mu']!r}): it grows with the "
                        "pair's load, which the formats' friction (a constant dry friction) cannot follow")
    for a in d.spec.get("actuators", []):
        name = a.get("name") or a.get("coordinate") or a.get("pair")
        if float(a.get("efficiency", 1.0)) != 1.0:
            lost.append(f"the efficiency {a['efficiency']!r} of actuator {name!r}: a loss that changes with the "
                        "direction of the power flow")
        if float(a.get("backdrive_efficiency", 1.0)) != 1.0:
            lost.append(f"the back-drive efficiency {a['backdrive_efficiency']!r} of actuator {name!r} (the gear's "
                        "efficiency while the load drives the motor)")
        limits = a.get("limits") or {}
        for key in ("continuous_torque", "max_speed", "torque_speed", "corner_speed"):
            if limits.get(key) is not None:
                lost.append(f"the {key} limit of actuator {name!r} (the formats clamp the torque only)")
    for dr in d.spec.get("drives", []):
        if "motion" in dr:
            lost.append(f"the prescribed motion of coordinate {dr['coordinate']!r} (the formats drive joints by effort)")
        elif "table" in dr:
            lost.append(f"the effort table of coordinate {dr['coordinate']!r}: a control signal, set it at run time "
                        "(the export holds its value at t = 0)")
    compliance = d.spec.get("compliance") or {}
    lost += [f"the elastic drive of actuator {e['actuator']!r} (stiffness {e['stiffness']!r}): the exports' "
             "transmissions are rigid" for e in compliance.get("drives", [])]
    lost += [f"the compliance of pair {e['pair']!r} (stiffness {e['stiffness']!r}): the exports' joints are rigid"
             for e in compliance.get("pairs", [])]
    lost += [f"the elastic link {e['body']!r}: the exports' links are rigid" for e in compliance.get("links", [])]
    return lost
