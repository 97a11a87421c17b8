"""Mechanisms by their dimensions, in Python: :class:`Builder` collects points, bodies, pairs
and coordinates into the model dict a model file holds (``planardyn docs model-format``), so
that ``pdy.from_dict(b.model)`` (or :meth:`Builder.build`) gives the mechanism and
:meth:`Builder.write` the file.

Lengths and angles are numbers in SI (m, rad) or text with their unit (``"120 mm"``,
``"30 deg"``), as in a model file; a point is given by its coordinates or by construction
(:meth:`~Builder.polar`, :meth:`~Builder.circles`, :meth:`~Builder.along`,
:meth:`~Builder.line_circle`), which the dict keeps as written and the loader places. The
mechanism's parts come whole: a :meth:`~Builder.crank` (its tip at a length and an angle, its
pivot, its input coordinate), an RRR :meth:`~Builder.dyad` (two links meeting where their
circles do, on the side named), a :meth:`~Builder.slider` (a block on a guide), and the pairs
(:meth:`~Builder.revolute`, :meth:`~Builder.prismatic`, :meth:`~Builder.slot`,
:meth:`~Builder.gear`).

The assembly side of a construction from two circles about A and B: ``"left"`` puts the point
on the counter-clockwise side of the directed line A -> B (the drawing's y axis up), ``"right"``
on the clockwise side.
"""

from __future__ import annotations

import copy
import json
import math
import os
from collections.abc import Callable, Sequence
from typing import Any, Literal

from ._core import resolve_model
from .arguments import error
from .mechanism import Mechanism, from_dict
from .model_text import model_text

#: A length or an angle: a number (m or rad) or text with its unit ("120 mm", "30 deg").
Quantity = float | str
Vec = tuple[float, float]
Side = Literal["left", "right"]

__all__ = ["Builder", "Quantity", "Side"]


class Builder:
    """Collects a mechanism's points, bodies, pairs and coordinates into a model dict.

    ``name`` names the model, ``about`` says where its data come from, ``gravity`` [g_x, g_y]
    (m/s^2, default [0, -9.81]: the mechanism hangs in a vertical plane). Every method that
    adds a point, a body or a pair returns its name, so that calls can be chained into others.
    """

    def __init__(self, name: str, about: str = "", gravity: Sequence[Quantity] = (0.0, -9.81)) -> None:
        self._d: dict[str, Any] = {"name": name}
        if about:
            self._d["about"] = about
        self._d.update({"gravity": [_q(g) for g in gravity], "points": {}, "ground": [], "bodies": {}, "pairs": [],
                        "coordinates": []})
        self._placed: dict[str, Vec] | None = None

    # ------------------------------------------------------------------ points

    def point(self, name: str, xy: Sequence[Quantity], *, ground: bool = False) -> str:
        """A point at coordinates [x, y] (m or with a unit of length); ``ground``: the ground carries it."""
        return self._add_point(name, [_q(v) for v in xy], ground)

    def polar(self, name: str, start: str, length: Quantity, angle: Quantity, *,
              relative_to: tuple[str, str] | None = None, ground: bool = False) -> str:
        """The point at ``length`` from ``start`` in the direction ``angle`` (counter-clockwise
        from the x axis, or from the direction P -> Q of ``relative_to=(P, Q)``)."""
        c: dict[str, Any] = {"from": start, "length": _q(length), "angle": _q(angle)}
        if relative_to is not None:
            c["relative_to"] = list(relative_to)
        return self._add_point(name, c, ground)

    def circles(self, name: str, a: str, r_a: Quantity, b: str, r_b: Quantity, side: Side, *,
                ground: bool = False) -> str:
        """The point at ``r_a`` from ``a`` and ``r_b`` from ``b``, on the ``side`` of the
        directed line a -> b (``"left"``: counter-clockwise)."""
        return self._add_point(name, {"circles": [[a, _q(r_a)], [b, _q(r_b)]], "side": side}, ground)

    def along(self, name: str, a: str, b: str, *, distance: Quantity | None = None, fraction: float | None = None,
              ground: bool = False) -> str:
        """The point on the line a -> b at ``distance`` from a, or at ``fraction`` of the way (one of the two)."""
        c: dict[str, Any] = {"along": [a, b]}
        if distance is not None:
            c["distance"] = _q(distance)
        if fraction is not None:
            c["fraction"] = float(fraction)
        return self._add_point(name, c, ground)

    def line_circle(self, name: str, line: tuple[str, str], centre: str, radius: Quantity,
                    crossing: Literal["first", "second"], *, ground: bool = False) -> str:
        """Where the line through ``line = (P, Q)`` meets the circle of ``radius`` about
        ``centre``: the first or the second crossing going from P towards Q."""
        c = {"line": list(line), "circle": [centre, _q(radius)], "crossing": crossing}
        return self._add_point(name, c, ground)

    def ground(self, *names: str) -> None:
        """The ground carries these points (pivots, guides' ends)."""
        self._d["ground"] += [n for n in names if n not in self._d["ground"]]

    def xy(self, name: str) -> Vec:
        """Where a point is (m), its construction placed by the loader."""
        spec = self._known("point", name, self._d["points"])
        if isinstance(spec, list) and all(isinstance(v, float) for v in spec):
            return (spec[0], spec[1])
        if self._placed is None:
            skeleton = {"name": self._d["name"], "points": self._d["points"], "bodies": {}, "pairs": [],
                        "coordinates": []}
            text, _ = resolve_model(json.dumps(skeleton), "data", f"<Builder {self._d['name']!r}>")
            self._placed = {k: (v[0], v[1]) for k, v in json.loads(text)["points"].items()}
        return self._placed[name]

    def distance(self, a: str, b: str) -> float:
        """|ab| (m) in the drawing."""
        (xa, ya), (xb, yb) = self.xy(a), self.xy(b)
        return math.hypot(xb - xa, yb - ya)

    # ------------------------------------------------------------------ bodies

    def bar(self, name: str, points: Sequence[str], *, rho: float | None = None, mass: Quantity | None = None,
            about: str | None = None) -> str:
        """A uniform bar between its first two points, carrying all ``points``: of ``mass``
        (kg, or with a unit), or of ``rho`` kg per metre of its drawn length."""
        if len(points) < 2:
            raise error("points", f"bar {name!r}: a bar carries at least two points, got {list(points)!r}")
        p, q = points[0], points[1]
        body = self._body(name, points, about)
        body["uniform_bar"] = [p, q]
        body["mass"] = _mass(mass, rho, lambda: self.distance(p, q), name)
        return name

    def bars(self, rho: float, **links: Sequence[str]) -> None:
        """Uniform bars (``rho`` kg/m), each named by its keyword and carrying the points given."""
        for name, points in links.items():
            self.bar(name, points, rho=rho)

    def polygon(self, name: str, points: Sequence[str], outline: Sequence[str], rho: float,
                about: str | None = None) -> str:
        """A link of uniform bars (``rho`` kg/m) along the closed ``outline``, carrying ``points``."""
        body = self._body(name, points, about)
        body["parts"] = [{"uniform_bar": [a, b], "mass": rho * self.distance(a, b)}
                         for a, b in zip(outline, list(outline[1:]) + list(outline[:1]))]
        return name

    def block(self, name: str, point: str, mass: Quantity, inertia: Quantity, about: str | None = None) -> str:
        """A block (a slider): its mass (kg) at ``point``, its own inertia (kg m^2)."""
        body = self._body(name, [point], about)
        body.update({"mass": _q(mass), "inertia": _q(inertia), "com": point})
        return name

    def carry(self, body: str, *points: str) -> None:
        """``body`` carries these points too (a coupler point, a pin of a later pair)."""
        have = self._known("body", body, self._d["bodies"])["points"]
        have += [p for p in points if p not in have]

    # ------------------------------------------------------------------ pairs

    def revolute(self, name: str, at: str, a: str, b: str) -> str:
        """A pin at ``at`` between bodies ``a`` and ``b`` (``"ground"`` the fixed body)."""
        return self._pair({"type": "revolute", "name": name, "at": at, "bodies": [a, b]})

    def prismatic(self, name: str, at: str, a: str, b: str, *, axis: Sequence[float] | None = None,
                  along: tuple[str, str] | None = None) -> str:
        """``b`` slides without turning along a guide of ``a`` through ``at``: direction ``axis`` or the line ``along``."""
        return self._pair({"type": "prismatic", "name": name, "at": at, "bodies": [a, b], **_guide(axis, along)})

    def slot(self, name: str, at: str, a: str, b: str, *, axis: Sequence[float] | None = None,
             along: tuple[str, str] | None = None) -> str:
        """``b``'s pin ``at`` slides and turns in a slot of ``a``: direction ``axis`` or the line ``along``."""
        return self._pair({"type": "slot", "name": name, "at": at, "bodies": [a, b], **_guide(axis, along)})

    def gear(self, name: str, a: str, b: str, centers: Sequence[str], radii: Sequence[Quantity], *,
             internal: bool = False, carrier: str | None = None, rack: tuple[str, str] | None = None) -> str:
        """The pitch circles of ``a``'s and ``b``'s gears (centres ``centers``, pitch radii
        ``radii``, m or with a unit) roll without slip; ``internal`` for a ring gear, ``rack``
        for b's pitch line through two of its points (then one centre and one radius)."""
        pair: dict[str, Any] = {"type": "gear", "name": name, "bodies": [a, b], "centers": list(centers),
                                "radii": [_q(r) for r in radii]}
        if internal:
            pair["internal"] = True
        if carrier is not None:
            pair["carrier"] = carrier
        if rack is not None:
            pair["rack"] = list(rack)
        return self._pair(pair)

    def hinges(self, *joints: tuple[str, str, str]) -> None:
        """Revolute pairs given as (at, a, b), each named ``a_b`` after the bodies it joins."""
        for at, a, b in joints:
            self.revolute(f"{a}_{b}", at, a, b)

    def coordinate(self, name: str, pair: str, value: Quantity | dict[str, list[str]], about: str | None = None) -> str:
        """An input: the pair ``pair``'s coordinate, drawn at ``value`` (rad or m, with a unit,
        or ``{"angle": [P, Q]}`` / ``{"distance": [P, Q]}``, a measure of the drawing)."""
        c: dict[str, Any] = {"name": name, "pair": pair, "value": value if isinstance(value, dict) else _q(value)}
        if about:
            c["about"] = about
        self._d["coordinates"].append(c)
        return name

    # ------------------------------------------------------------------ parts by their dimensions

    def crank(self, body: str, pivot: str, tip: str, length: Quantity, angle: Quantity, *, on: str = "ground",
              rho: float | None = None, mass: Quantity | None = None, coordinate: str | None = None) -> str:
        """A crank: the uniform bar ``body`` (``rho`` kg/m or ``mass`` kg) from ``pivot``
        (carried by ``on``) to its ``tip`` at ``length`` and ``angle``, pinned at the pivot by
        the pair ``<on>_<body>``; with ``coordinate``, the input of that name, the crank's
        absolute angle (the line pivot -> tip, rad). Returns the pair's name."""
        self.polar(tip, pivot, length, angle)
        self.bar(body, [pivot, tip], rho=rho, mass=mass)
        if on == "ground":
            self.ground(pivot)
        pin = self.revolute(f"{on}_{body}", pivot, on, body)
        if coordinate is not None:
            self.coordinate(coordinate, pin, {"angle": [pivot, tip]}, about=f"absolute angle of {pivot}->{tip} (rad)")
        return pin

    def dyad(self, links: tuple[str, str], joint: str, a: str, r_a: Quantity, b: str, r_b: Quantity, side: Side, *,
             ends: tuple[str, str], rho: float | None = None, masses: tuple[Quantity, Quantity] | None = None) -> str:
        """An RRR dyad: the links ``links = (l_a, l_b)`` from ``a`` (carried by ``ends[0]``)
        and ``b`` (carried by ``ends[1]``), ``r_a`` and ``r_b`` long, pinned to each other at
        ``joint``, where their circles meet on the ``side`` of a -> b. Uniform bars (``rho``
        kg/m or ``masses`` kg), pins named ``<end>_<link>`` and ``<l_a>_<l_b>``. Returns ``joint``."""
        self.circles(joint, a, r_a, b, r_b, side)
        for k, (link, end, at) in enumerate(zip(links, ends, (a, b))):
            self.bar(link, [at, joint], rho=rho, mass=None if masses is None else masses[k])
            if end == "ground":
                self.ground(at)
            self.revolute(f"{end}_{link}", at, end, link)
        self.revolute(f"{links[0]}_{links[1]}", joint, links[0], links[1])
        return joint

    def slider(self, body: str, point: str, mass: Quantity, inertia: Quantity, *, guide: str = "ground",
               axis: Sequence[float] | None = None, along: tuple[str, str] | None = None,
               coordinate: str | None = None) -> str:
        """A slider: the block ``body`` at ``point`` on the prismatic pair ``<guide>_<body>``
        of the body ``guide`` (direction ``axis`` or the line ``along``); with ``coordinate``,
        the input of that name, its travel from the drawing (m). Returns the pair's name."""
        self.block(body, point, mass, inertia)
        pair = self.prismatic(f"{guide}_{body}", point, guide, body, axis=axis, along=along)
        if coordinate is not None:
            self.coordinate(coordinate, pair, 0.0, about=f"travel of {body} along its guide from the drawing (m)")
        return pair

    # ------------------------------------------------------------------ the model

    @property
    def model(self) -> dict[str, Any]:
        """The model dict (a copy): the model file's schema, constructions as written."""
        return copy.deepcopy(self._d)

    def build(self, source: str | None = None) -> Mechanism:
        """The validated :class:`~planardyn.Mechanism` (``pdy.from_dict(self.model)``)."""
        return from_dict(self._d, source=source or f"<Builder {self._d['name']!r}>")

    def write(self, path: str | os.PathLike[str]) -> None:
        """Write the model file: JSON for ``.json``, else YAML (:func:`~planardyn.model_text.model_text`)."""
        json_file = os.fspath(path).lower().endswith(".json")
        text = json.dumps(self._d, indent=2, ensure_ascii=False) + "\n" if json_file else model_text(self._d)
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)

    # ------------------------------------------------------------------ helpers

    def _add_point(self, name: str, spec: Any, ground: bool) -> str:
        self._d["points"][name] = spec
        self._placed = None
        if ground:
            self.ground(name)
        return name

    def _known(self, kind: str, name: str, entries: dict[str, Any]) -> Any:
        if name not in entries:
            raise error(kind, f"unknown {kind} {name!r}; the {kind}s so far: {', '.join(entries) or 'none'} "
                              f"(add it first)")
        return entries[name]

    def _body(self, name: str, points: Sequence[str], about: str | None) -> dict[str, Any]:
        body: dict[str, Any] = {"points": list(points)}
        if about:
            body["about"] = about
        self._d["bodies"][name] = body
        return body

    def _pair(self, pair: dict[str, Any]) -> str:
        self._d["pairs"].append(pair)
        return str(pair["name"])


def _q(v: Quantity) -> Quantity:
    """A quantity as the dict holds it: text as written, a number as a float."""
    return v if isinstance(v, str) else float(v)


def _mass(mass: Quantity | None, rho: float | None, length: Callable[[], float], body: str) -> Quantity:
    if mass is not None and rho is None:
        return _q(mass)
    if rho is not None and mass is None:
        return float(rho) * length()
    raise error("mass", f"body {body!r}: give one of mass (kg) and rho (kg per metre of its length)")


def _guide(axis: Sequence[float] | None, along: tuple[str, str] | None) -> dict[str, Any]:
    """A guide's direction as the dict holds it: ``axis`` as a unit vector, or ``along``."""
    if axis is not None:
        n = math.hypot(float(axis[0]), float(axis[1]))
        if not (n > 0.0 and math.isfinite(n)):
            raise error("axis", f"a guide's direction must be a finite non-zero vector, got {list(axis)!r}")
        return {"axis": [float(axis[0]) / n, float(axis[1]) / n]}
    return {"along": list(along)} if along is not None else {}
