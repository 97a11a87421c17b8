"""Assembly modes (all solutions x of the direct position problem at given inputs q) and
working modes (all inputs q that put the end effector at X), each of which can be picked as
a re-drawn :class:`~planardyn.Mechanism` to simulate in.

The core's position analysis continues from the drawing, so it only ever finds the drawn
branch. Other branches are reached by changing the drawing:

- **dyad mirrors**: a dyad is an RRR Assur group of two binary links b1 = (E1, P),
  b2 = (E2, P) joined by a revolute pair at the elbow P (the core's structural analysis finds
  them). Reflecting P across the line E1-E2 keeps both link lengths and gives the other
  closure of that dyad; every subset of the dyads is mirrored (at most 2^6 variants).
- **random re-draws** (any mechanism): the drawing (or a mirror) is assembled at random inputs
  and re-drawn there; continuation from that drawing to q can end on another branch.

Solutions are told apart by the world positions of their named points (``DEDUP_TOL``) and
named by the dyads' orientations: per dyad ``'+'`` when cross(E1 - P, E2 - P) > 0 (for the
drawn five-bar: elbow up), else ``'-'``.
"""

from __future__ import annotations

import copy
import itertools
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._core import AssemblyError, SingularityError
from .._core import structure as native_structure
from .tolerances import DEDUP_TOL, WORKING_TOL

if TYPE_CHECKING:
    from ..mechanism import Mechanism
    from .effector import EndEffector

FloatArray = NDArray[np.float64]

# At most this many dyads are mirrored in every combination (2^6 variants).
MAX_MIRRORED_DYADS = 6


def _rot(a: float) -> FloatArray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s], [s, c]])


def _cross(a: FloatArray, b: FloatArray) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


@dataclass
class Mode:
    """One assembly or working mode.

    ``name`` (e.g. ``'+'``, or ``'left -, right +'`` for a 5R working mode), ``q`` (m,) inputs
    (rad or m), ``x`` (3n,) body coordinates as the mechanism it was solved on counts them,
    ``points`` (P, 2) world positions of the named points (m, the convention-free
    description), ``sigma_min`` the type II measure there (0 at a singularity).
    :meth:`mechanism` gives the model re-drawn in this mode.
    """

    name: str
    q: FloatArray
    x: FloatArray
    points: FloatArray
    sigma_min: float
    signs: tuple[int, ...] = ()
    _source: Any = field(default=None, repr=False, compare=False)

    def mechanism(self) -> Mechanism:
        """The model re-drawn in this mode: points moved to this configuration, centres of
        mass, guide axes and spring rests carried along, coordinate values set to q.
        Simulating it (q0 = q by default) runs on this branch."""
        from ..mechanism import from_dict

        return from_dict(redraw(self._source, self.q, self.x), source=f"<{self._source.name}, mode {self.name}>")


# ---------------------------------------------------------------------- model dict surgery


def redraw(mech: Mechanism, q: ArrayLike, x: ArrayLike) -> dict[str, Any]:
    """The model dict of ``mech`` drawn at configuration (q, x) instead of its drawing.

    Each body moves rigidly from its drawn pose x0 to x: named points to their positions,
    explicit ``com`` coordinates (also of parts) and prismatic ``axis`` directions with it;
    torsional spring rests are shifted so the springs exert the same efforts; linear springs
    without ``rest_length`` get their drawn length; coordinate ``value`` becomes q.
    """
    q = np.asarray(q, dtype=float)
    x = np.asarray(x, dtype=float)
    d = copy.deepcopy(mech.to_dict())
    x0 = mech.x0
    names = mech.body_names
    old_points = {k: np.asarray(v, dtype=float) for k, v in d["points"].items()}

    def move(body: str, p: ArrayLike) -> FloatArray:
        p = np.asarray(p, dtype=float)
        if body == "ground":
            return p
        i = names.index(body)
        return x[3 * i:3 * i + 2] + _rot(x[3 * i + 2] - x0[3 * i + 2]) @ (p - x0[3 * i:3 * i + 2])

    def turn(body: str) -> float:
        if body == "ground":
            return 0.0
        i = names.index(body)
        return float(x[3 * i + 2] - x0[3 * i + 2])

    new_points = mech.point_positions(x)
    for name, p in zip(mech.point_names, new_points):
        if name in d["points"]:
            d["points"][name] = [float(p[0]), float(p[1])]
    for bname, body in d.get("bodies", {}).items():
        for part in [body, *body.get("parts", [])]:
            com = part.get("com")
            if isinstance(com, list):
                part["com"] = move(bname, com).tolist()
    pairs = {p["name"]: p for p in d.get("pairs", []) if "name" in p}
    for p in d.get("pairs", []):
        if p.get("axis") is not None:
            p["axis"] = (_rot(turn(p["bodies"][0])) @ np.asarray(p["axis"], dtype=float)).tolist()
    for load in d.get("loads", []):
        kind = load.get("type")
        if kind == "torsional_spring" and load.get("pair") in pairs:
            pair = pairs[load["pair"]]
            a, b = pair["bodies"]
            if pair.get("type") == "revolute":
                shift = turn(b) - turn(a)
            else:  # displacement of b's copy of `at` along the guide since the drawing
                at = old_points[pair["at"]]
                if pair.get("axis") is not None:
                    axis0 = np.asarray(mech.to_dict()["pairs"][d["pairs"].index(pair)]["axis"], dtype=float)
                else:
                    P1, P2 = (old_points[k] for k in pair["along"])
                    axis0 = P2 - P1
                axis = _rot(turn(a)) @ (axis0 / np.linalg.norm(axis0))
                shift = float((move(b, at) - move(a, at)) @ axis)
            load["rest"] = float(load.get("rest", 0.0)) - shift
        elif kind == "spring" and load.get("rest_length") is None:
            (_, pa), (_, pb) = load["between"]
            load["rest_length"] = float(np.linalg.norm(old_points[pa] - old_points[pb]))
    for k, c in enumerate(d.get("coordinates", [])):
        c["value"] = float(q[k])
    return d


def dyads(mech: Mechanism) -> list[tuple[str, str, str]]:
    """The mirrorable dyads as (E1, P, E2) point names: the core's class II RRR groups
    (``planardyn::structure``) of two binary links (E1, P) and (E2, P), P the point of
    their inner pair."""
    at = {p["name"]: p["point"] for p in mech.pairs}
    points = {b: [n for n, _ in bp] for b, bp in zip(mech.body_names, mech.body_points)}
    out = []
    for g in native_structure(mech._native)["groups"]:
        if g["class"] != 2 or g["kind"] != "RRR":
            continue
        P = at[g["inner_pairs"][0]]
        ends = []
        for link in g["links"]:  # a link of two locked bodies ('a+b') is no binary link
            pts = points.get(link, [])
            if len(pts) != 2 or P not in pts:
                break
            ends.append(pts[0] if pts[1] == P else pts[1])
        if len(ends) == 2 and ends[0] != ends[1]:
            out.append((ends[0], P, ends[1]))
    return out


def _mirror(model: dict[str, Any], mech: Mechanism, dyad: tuple[str, str, str]) -> None:
    """Reflect the elbow of a dyad across E1-E2 in the model dict (in place): each link turns
    rigidly about its other end, so explicit centres of mass turn with it."""
    E1, P, E2 = dyad
    pts = model["points"]
    e1, p, e2 = (np.asarray(pts[k], dtype=float) for k in (E1, P, E2))
    t = (e2 - e1) / np.linalg.norm(e2 - e1)
    foot = e1 + t * ((p - e1) @ t)
    p_new = 2 * foot - p
    pts[P] = p_new.tolist()
    for body in model.get("bodies", {}).values():
        plist = body.get("points", [])
        if P not in plist or len(plist) != 2:
            continue
        E = E1 if E1 in plist else E2
        e = np.asarray(pts[E], dtype=float)
        ang = np.arctan2(*(p_new - e)[::-1]) - np.arctan2(*(p - e)[::-1])
        for part in [body, *body.get("parts", [])]:
            if isinstance(part.get("com"), list):
                part["com"] = (e + _rot(ang) @ (np.asarray(part["com"], dtype=float) - e)).tolist()


def _variants(mech: Mechanism) -> list[Mechanism]:
    """The mechanism with every subset of its (first MAX_MIRRORED_DYADS) dyads mirrored."""
    from ..mechanism import from_dict

    dy = dyads(mech)[:MAX_MIRRORED_DYADS]
    out = [mech]
    base = mech.to_dict()
    for k in range(1, len(dy) + 1):
        for subset in itertools.combinations(dy, k):
            model = copy.deepcopy(base)
            for dyad in subset:
                _mirror(model, mech, dyad)
            try:
                out.append(from_dict(model, source=f"<{mech.name} mirrored>"))
            except Exception:  # noqa: BLE001 - a mirror the loader refuses is just not a start
                continue
    return out


def _signs(mech: Mechanism, points: FloatArray, dy: list[tuple[str, str, str]]) -> tuple[int, ...]:
    idx = {n: i for i, n in enumerate(mech.point_names)}
    out = []
    for E1, P, E2 in dy:
        c = _cross(points[idx[E1]] - points[idx[P]], points[idx[E2]] - points[idx[P]])
        out.append(1 if c > 0 else -1)
    return tuple(out)


def _name_all(modes: list[Mode], prefix: list[str] | None = None) -> None:
    """Names from the signs ('+'/'-' per dyad, with a prefix per dyad if given); repeated
    names get '#2', '#3'..."""
    seen: dict[str, int] = {}
    for mode in modes:
        if mode.signs:
            parts = ["+" if s > 0 else "-" for s in mode.signs]
            base = ", ".join(f"{p} {s}" for p, s in zip(prefix, parts)) if prefix else " ".join(parts)
        else:
            base = "mode"
        seen[base] = seen.get(base, 0) + 1
        mode.name = base if seen[base] == 1 else f"{base} #{seen[base]}"
    if any(v > 1 for v in seen.values()):  # the first of a repeated name gets #1
        counts = dict(seen)
        for mode in modes:
            if counts.get(mode.name, 0) > 1:
                mode.name = f"{mode.name} #1"


def _dedup_add(found: list[tuple[Mechanism, FloatArray, FloatArray, FloatArray]], src: Mechanism, q: FloatArray,
               x: FloatArray) -> None:
    pts = src.point_positions(x)
    if all(np.max(np.abs(pts - f[3])) > DEDUP_TOL for f in found):
        found.append((src, q.copy(), x.copy(), pts))


def _to_modes(mech: Mechanism, found: list[tuple[Mechanism, FloatArray, FloatArray, FloatArray]],
              prefix: list[str] | None = None) -> list[Mode]:
    dy = dyads(mech)
    modes = []
    for src, q, x, pts in found:
        try:
            sigma = float(src.kinematics(q, x_start=x)["sigma_min"])
        except SingularityError:
            sigma = 0.0
        modes.append(Mode("", q, x, pts, sigma, _signs(mech, pts, dy), src))
    return modes


# ---------------------------------------------------------------------- direct problem


def assembly_modes(mech: Mechanism, q: ArrayLike | None = None, starts: int = 64, seed: int = 0) -> list[Mode]:
    """All assembly modes found at inputs q (default the drawn ones): the configurations x
    that close every loop with the inputs fixed (direct position problem).

    Starts: the drawing with every subset of its dyads mirrored, and ``starts`` random
    re-draws (each variant assembled at random inputs, re-drawn there, continued to q).
    Returns the distinct solutions (points within ``DEDUP_TOL``), the drawn branch first
    when it assembles, named by the dyad signs.
    """
    from ..mechanism import from_dict

    q = mech.drawn_q if q is None else np.asarray(q, dtype=float)
    rng = np.random.default_rng(seed)
    variants = _variants(mech)
    found: list[tuple[Any, FloatArray, FloatArray, FloatArray]] = []
    for v in variants:
        try:
            _dedup_add(found, v, q, v.assemble(q))
        except (AssemblyError, SingularityError):
            pass
    half = np.array([np.pi if k == "angle" else 0.3 * mech.scale for k in mech.coordinate_kinds])
    for k in range(starts):
        v = variants[k % len(variants)]
        q1 = v.drawn_q + rng.uniform(-half, half)
        try:
            x1 = v.assemble(q1)
            w = from_dict(redraw(v, q1, x1), source=f"<{mech.name} re-drawn>")
            _dedup_add(found, w, q, w.assemble(q))
        except (AssemblyError, SingularityError, ValueError):
            continue
    modes = _to_modes(mech, found)
    _name_all(modes)
    return modes


# ---------------------------------------------------------------------- inverse problem


def _five_bar_legs(ee: EndEffector) -> list[dict[str, Any]] | None:
    """For a 5R (two inputs on ground-pivoted binary links A_k C_k, distal binary links
    C_k P meeting at the end-effector point) the two legs' geometry, else None."""
    mech = ee.mech
    if mech.dof != 2 or ee.dim != 2:
        return None
    d = mech.to_dict()
    pairs = {p.get("name"): p for p in d.get("pairs", [])}
    bodies = d.get("bodies", {})
    P = ee.point
    legs = []
    for c in d.get("coordinates", []):
        pair = pairs.get(c.get("pair"))
        if pair is None or pair.get("type") != "revolute" or pair["bodies"][0] != "ground":
            return None
        prox = pair["bodies"][1]
        A = pair["at"]
        ppts = bodies[prox].get("points", [])
        if len(ppts) != 2 or A not in ppts:
            return None
        C = ppts[0] if ppts[1] == A else ppts[1]
        distal = [b for b, body in bodies.items()
                  if b != prox and set(body.get("points", [])) == {C, P}]
        if len(distal) != 1:
            return None
        legs.append(dict(A=A, C=C, prox=prox, distal=distal[0], value=float(c["value"])))
    if len({leg["distal"] for leg in legs}) != 2 or len(bodies) != 4:
        return None
    return legs


def _five_bar_modes(ee: EndEffector, X: FloatArray, legs: list[dict[str, Any]]) -> list[tuple[FloatArray, dict[str, FloatArray]]]:
    mech = ee.mech
    pts0 = {k: np.asarray(v, dtype=float) for k, v in mech.to_dict()["points"].items()}
    P = ee.point
    per_leg = []
    for leg in legs:
        a, c0 = pts0[leg["A"]], pts0[leg["C"]]
        l1, l2 = np.linalg.norm(c0 - a), np.linalg.norm(pts0[P] - c0)
        dvec = X - a
        r = float(np.linalg.norm(dvec))
        if r == 0 or r > l1 + l2 or r < abs(l1 - l2):
            return []
        along = (r * r + l1 * l1 - l2 * l2) / (2 * r)
        h = np.sqrt(max(l1 * l1 - along * along, 0.0))
        e, n = dvec / r, np.array([-dvec[1], dvec[0]]) / r
        sols = []
        for side in (+1, -1):  # +1: C left of A->X
            C = a + along * e + side * h * n
            ang = np.arctan2(*(C - a)[::-1]) - np.arctan2(*(c0 - a)[::-1])
            ang = (ang + np.pi) % (2 * np.pi) - np.pi  # rotation from the drawing, near 0
            sols.append((leg["value"] + ang, C))
        per_leg.append(sols)
    out = []
    for (q1, C1), (q2, C2) in itertools.product(*per_leg):
        out.append((np.array([q1, q2]), {legs[0]["C"]: C1, legs[1]["C"]: C2, P: X}))
    return out


def _pose_from_points(mech: Mechanism, new: dict[str, FloatArray]) -> FloatArray:
    """Body coordinates x that carry each body's drawn points rigidly to ``new`` (ground
    points stay); every mobile body needs two points with known positions."""
    pts0 = {k: np.asarray(v, dtype=float) for k, v in mech.to_dict()["points"].items()}
    known = {k: pts0[k] for k in mech.ground_points}
    known.update(new)
    x0 = mech.x0
    x = np.empty_like(x0)
    for i, bp in enumerate(mech.body_points):
        names = [n for n, _ in bp if n in known][:2]
        p, r = pts0[names[0]], pts0[names[1]]
        pn, rn = known[names[0]], known[names[1]]
        ang = np.arctan2(*(rn - pn)[::-1]) - np.arctan2(*(r - p)[::-1])
        x[3 * i:3 * i + 2] = pn + _rot(ang) @ (x0[3 * i:3 * i + 2] - p)
        x[3 * i + 2] = x0[3 * i + 2] + ang
    return x


def working_modes(ee: EndEffector, X: ArrayLike, starts: int = 64, seed: int = 0) -> list[Mode]:
    """All working modes found for end-effector position X: the inputs q (with the
    configuration) that put the end-effector point at X (inverse position problem).

    A 5R (detected from the model: two inputs on ground-pivoted links, distal links meeting
    at the end-effector point) is solved in closed form, each leg's 2R inverse kinematics
    giving two elbows: four modes named ``'<leg1 coordinate> +/-, <leg2 coordinate> +/-'``
    ('+': the elbow C_k to the left of A_k -> X). Any other mechanism: Newton with the
    end-effector Jacobian from ``starts`` random inputs on every dyad-mirror variant,
    named by the dyad signs.
    """
    mech = ee.mech
    X = np.asarray(X, dtype=float)
    legs = _five_bar_legs(ee)
    if legs is not None:
        modes = []
        for q, new in _five_bar_modes(ee, X, legs):
            x = _pose_from_points(mech, new)
            pts = mech.point_positions(x)
            src_mode = Mode("", q, x, pts, np.nan, (), mech)
            try:
                sigma = float(src_mode.mechanism().kinematics(q)["sigma_min"])
            except SingularityError:
                sigma = 0.0
            signs = []
            for leg in legs:
                a = mech.point_positions(mech.x0)[mech.point_names.index(leg["A"])]
                C = new[leg["C"]]
                signs.append(1 if _cross(X - a, C - a) > 0 else -1)
            modes.append(Mode("", q, x, pts, sigma, tuple(signs), mech))
        _name_all(modes, prefix=mech.coordinate_names)
        return modes
    from .effector import EndEffector as _EE

    rng = np.random.default_rng(seed)
    found: list[tuple[Any, FloatArray, FloatArray, FloatArray]] = []
    half = np.array([np.pi if k == "angle" else 0.5 * mech.scale for k in mech.coordinate_kinds])
    variants = _variants(mech)
    for k in range(starts):
        v = variants[k % len(variants)]
        ev = _EE(v, ee.point, ee.body if ee.dim == 3 else None)
        q1 = v.drawn_q if k < len(variants) else v.drawn_q + rng.uniform(-half, half)
        try:
            st = ev.solve(X, q1)
        except (AssemblyError, SingularityError, np.linalg.LinAlgError, ValueError):
            continue
        if np.max(np.abs(st.X[:2] - X[:2])) <= WORKING_TOL:
            _dedup_add(found, v, st.q, st.kin["x"])
    modes = _to_modes(mech, found)
    _name_all(modes)
    return modes


__all__ = ["Mode", "assembly_modes", "dyads", "redraw", "working_modes"]
