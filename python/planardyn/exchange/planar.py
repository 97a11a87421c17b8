"""The import side: a planar mechanism read from a description file, as a model dict.

The readers (MJCF, URDF) find the bodies, their joints and their loop closures in the world
frame of the file's reference configuration (qpos = 0, the joints at 0), and hand them to a
:class:`Builder`, which names the points, writes the pairs and, where the file does not say
which joints are the coordinates, picks them: the actuated joints first, then the tree
joints in the file's order, each kept when it is independent of the pair constraints and of
the coordinates kept so far (the rank of the constraint Jacobian in the drawing grows).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .tree import GROUND, ExchangeError, Vec

#: Two points closer than this, relative to the mechanism's size, are the same point: a
#: closure's two anchors must meet in the drawing (a file's 17 significant digits give
#: ~1e-16; a CAD export rounded to 1e-6 m on a 1 m mechanism still passes).
SAME_POINT = 1e-6
#: A Jacobian's singular values below this (relative to the largest) count as zero.
RANK_TOL = 1e-9


@dataclass
class Builder:
    """Collects a mechanism as read; :meth:`model` writes the model dict."""

    name: str
    source: str
    gravity: Vec = field(default_factory=lambda: np.zeros(2))
    points: dict[str, Vec] = field(default_factory=dict)
    carried: dict[str, list[str]] = field(default_factory=lambda: {GROUND: []})
    bodies: dict[str, dict[str, Any]] = field(default_factory=dict)
    pairs: list[dict[str, Any]] = field(default_factory=list)
    coordinates: list[dict[str, Any]] = field(default_factory=list)
    preferred: list[str] = field(default_factory=list)  # pair names to try first as coordinates
    loads: list[dict[str, Any]] = field(default_factory=list)
    drives: list[dict[str, Any]] = field(default_factory=list)
    actuators: list[dict[str, Any]] = field(default_factory=list)
    parts: dict[str, list[tuple[float, float, Vec]]] = field(default_factory=dict)  # body -> (m, Izz, com) parts

    def part(self, body: str, mass: float, izz: float, com: Vec) -> None:
        """A rigid part of a body: mass (kg), moment about z through its centre (kg m^2), centre (m)."""
        if body != GROUND:  # mass on the fixed base does not move
            self.parts.setdefault(body, []).append((mass, izz, np.asarray(com[:2], dtype=float)))

    def masses(self, where: str) -> None:
        """Each body's mass, centre of mass and inertia about it, from its parts."""
        for body, parts in self.parts.items():
            m = sum(part[0] for part in parts)
            com = np.sum([part[0] * part[2] for part in parts], axis=0) / m
            inertia = sum(i + mi * float(np.sum((c - com) ** 2)) for mi, i, c in parts)
            self.body(body, m, inertia, com, f"{where}: body {body!r}")

    def gear(self, name: str, follow: str, lead: str, ratio: float) -> str | None:
        """A linear coupling q_follow = ratio q_lead of two pairs on one carrier as a gear
        pair (two revolute pairs) or a rack and pinion (a prismatic pair following a
        revolute one), its radii from the ratio and the drawn centres (docs/model-format.md);
        or the reason it is not one."""
        pairs = {p["name"]: p for p in self.pairs}
        pf, pl = pairs[follow], pairs[lead]
        carrier = set(pf["bodies"]) & set(pl["bodies"])
        if pl["type"] != "revolute" or len(carrier) != 1:
            return "the leader must be a gear's revolute joint, and both joints must hold their bodies to one carrier"
        c = carrier.pop()
        s_a = 1.0 if pl["bodies"][0] == c else -1.0  # the gear's turn relative to the carrier per unit of joint
        s_b = 1.0 if pf["bodies"][0] == c else -1.0
        a, b = (next(x for x in p["bodies"] if x != c) for p in (pl, pf))
        entry: dict[str, Any] = {"type": "gear", "name": name, "bodies": [a, b]}
        if c != GROUND:
            entry["carrier"] = c
        center = self.points[pl["at"]]
        if pf["type"] == "prismatic":
            r_a = abs(ratio)
            e = np.asarray(pf["axis"], dtype=float) / np.linalg.norm(pf["axis"])
            sigma = ratio / (r_a * s_a * s_b)  # tree.py's ratio with P -> Q along the guide's axis
            pitch = center + sigma * r_a * np.array([e[1], -e[0]])  # on the pinion's right for sigma = +1
            entry.update(centers=[pl["at"]], radii=[r_a],
                         rack=[self.point(b, f"{name}_{k}", pitch + k * r_a * e) for k in (0, 1)])
        elif pf["type"] == "revolute":
            rho = -ratio * s_a * s_b  # r_a / r_b, negative inside a ring gear
            r_b = float(np.linalg.norm(self.points[pf["at"]] - center)) / abs(1.0 + rho)  # |AB| = |r_a +- r_b|
            entry.update(centers=[pl["at"], pf["at"]], radii=[abs(rho) * r_b, r_b])
            if rho < 0:
                entry["internal"] = True
        else:
            return "the follower must be a gear's revolute joint or a rack's prismatic joint"
        self.pairs.append(entry)
        return None

    def body(self, name: str, mass: float, inertia: float, com: Vec, where: str) -> None:
        if not (mass > 0.0 and inertia > 0.0):
            raise ExchangeError(f"{where}: mass {mass!r} kg and moment of inertia about z {inertia!r} kg m^2 must "
                                "both be > 0 (planardyn integrates every body; give the link its mass properties)")
        self.bodies[name] = {"mass": float(mass), "inertia": float(inertia), "com": [float(com[0]), float(com[1])]}

    def point(self, body: str, hint: str, p: Vec) -> str:
        """The name of a point carried by ``body`` at p (m): the body's point there, else
        the point named ``hint`` if it is there, else a new one named from ``hint``."""
        p = np.asarray(p[:2], dtype=float)
        tol = SAME_POINT * max(1.0, float(np.max(np.abs(p))))
        own = [n for n in self.carried.get(body, []) if np.linalg.norm(self.points[n] - p) <= tol]
        if own:
            return own[0]
        name, k = hint, 1
        while name in self.points and np.linalg.norm(self.points[name] - p) > tol:
            k += 1
            name = f"{hint}_{k}"
        self.points.setdefault(name, p)
        if name not in self.carried.setdefault(body, []):
            self.carried[body].append(name)
        return name

    def share(self, body: str, point: str) -> str:
        """Let ``body`` carry an existing point too (a pin joins two bodies at one point)."""
        if point not in self.carried.setdefault(body, []):
            self.carried[body].append(point)
        return point

    def pair(self, kind: str, name: str, a: str, b: str, at: str, axis: Vec | None = None) -> None:
        entry: dict[str, Any] = {"type": kind, "name": name, "at": at, "bodies": [a, b]}
        if axis is not None:
            entry["axis"] = [float(axis[0]), float(axis[1])]
        self.pairs.append(entry)

    def choose_coordinates(self) -> None:
        """One coordinate per degree of freedom on independent pairs, named after them, 0
        in the drawing (unless the file listed them already)."""
        if not self.coordinates:
            self.coordinates = [{"name": p, "pair": p, "value": 0.0} for p in self._independent()]

    def model(self) -> dict[str, Any]:
        """The model dict (``planardyn.from_dict`` builds the Mechanism)."""
        self.choose_coordinates()
        model: dict[str, Any] = {
            "name": self.name,
            "about": f"imported from {self.source} by planardyn.exchange",
            "gravity": [float(g) for g in self.gravity],
            "points": {n: [float(p[0]), float(p[1])] for n, p in self.points.items()},
            "ground": self.carried[GROUND],
            "bodies": {n: {"points": self.carried[n], **b} for n, b in self.bodies.items()},
            "pairs": self.pairs,
            "coordinates": self.coordinates,
        }
        for key in ("loads", "drives", "actuators"):
            if getattr(self, key):
                model[key] = getattr(self, key)
        return model

    # -------------------------------------------------------------- the coordinates

    def _rows(self, pair: dict[str, Any], motion: bool) -> np.ndarray:
        """A pair's constraint rows (motion False) or its relative rate (True) on the 3n body
        velocities [vx, vy, w] per body, in the drawing."""
        names = list(self.bodies)
        p = self.points[pair["centers"][0] if pair["type"] == "gear" else pair["at"]]

        def point_velocity(body: str, sign: float) -> np.ndarray:
            rows = np.zeros((2, 3 * len(names)))
            if body != GROUND:
                k = names.index(body)
                r = p - np.asarray(self.bodies[body]["com"])
                rows[:, 3 * k: 3 * k + 3] = sign * np.array([[1.0, 0.0, -r[1]], [0.0, 1.0, r[0]]])
            return rows

        def turn(body: str, sign: float) -> np.ndarray:
            row = np.zeros((1, 3 * len(names)))
            if body != GROUND:
                row[0, 3 * names.index(body) + 2] = sign
            return row

        a, b = pair["bodies"]
        if pair["type"] == "gear":  # r_a w_a + r_b w_b = 0 relative to the carrier; a rack's travel
            c = pair.get("carrier", GROUND)
            r_a = pair["radii"][0]
            if pair.get("rack"):
                e = self.points[pair["rack"][1]] - self.points[pair["rack"][0]]
                e /= np.linalg.norm(e)
                r = self.points[pair["rack"][0]] - p
                sigma = 1.0 if e[0] * r[1] - e[1] * r[0] < 0 else -1.0
                p = self.points[pair["rack"][0]]
                return sigma * r_a * (turn(a, 1.0) + turn(c, -1.0)) - e @ (point_velocity(b, 1.0) + point_velocity(c, -1.0))
            r_b = pair["radii"][1] * (-1.0 if pair.get("internal") else 1.0)
            return r_a * (turn(a, 1.0) + turn(c, -1.0)) + r_b * (turn(b, 1.0) + turn(c, -1.0))
        slip = point_velocity(b, 1.0) + point_velocity(a, -1.0)
        spin = turn(b, 1.0) + turn(a, -1.0)
        if pair["type"] == "revolute":
            return spin if motion else slip
        u = np.asarray(pair["axis"], dtype=float) / np.linalg.norm(pair["axis"])
        along, across = u @ slip, np.array([-u[1], u[0]]) @ slip
        if motion:
            return along[None, :]
        return across[None, :] if pair["type"] == "slot" else np.vstack([spin, across[None, :]])

    def _independent(self) -> list[str]:
        """Pair names for the coordinates: preferred ones, then the others, each kept when
        it raises the rank of [pair constraints; coordinates kept]."""
        phi = np.vstack([self._rows(p, False) for p in self.pairs]) if self.pairs else np.zeros((0, 3 * len(self.bodies)))

        def rank(m: np.ndarray) -> int:
            s = np.linalg.svd(m, compute_uv=False) if m.size else np.zeros(0)
            return int(np.sum(s > RANK_TOL * (s[0] if s.size else 1.0)))

        mobility = 3 * len(self.bodies) - rank(phi)
        order = [p for p in self.preferred] + [p["name"] for p in self.pairs if p["name"] not in self.preferred]
        by_name = {p["name"]: p for p in self.pairs}
        chosen: list[str] = []
        for name in order:
            if len(chosen) == mobility:
                break
            trial = np.vstack([phi] + [self._rows(by_name[c], True) for c in chosen + [name]])
            if rank(trial) == rank(phi) + len(chosen) + 1:
                chosen.append(name)
        if len(chosen) != mobility:
            raise ExchangeError(f"{self.source}: found {len(chosen)} independent joint(s) for a mobility of {mobility}")
        return chosen
