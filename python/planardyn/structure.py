"""Structural analysis of a mechanism: links and pairs, mobility, loops, Assur groups.

``analyse(mech) -> Structure`` and ``report(mech) -> str`` (printed by ``planardyn check``).
Notation: n mobile bodies (links, the ground not counted), p pairs, m coordinates.

- **Mobility** two ways: Chebyshev-Grubler-Kutzbach 3n - 2p (counts constraints), and
  3n - rank(Phi_x) from the pair-constraint Jacobian at the drawing (counts *independent*
  constraints). They differ by the number of redundant constraints 2p - rank; the pairs
  involved are those carrying a self-stress: a vector lambda != 0 with Phi_x^T lambda = 0,
  reactions in equilibrium without any load (so the reactions are not unique).
- **Loops**: p - (n + 1) + 1 independent loops for a connected mechanism; a basis from the
  pairs outside a spanning tree of the body-pair graph.
- **Assur groups**: lock the input pairs (a link driven from ground becomes part of the
  fixed frame; the two links of a relative input become one rigid link), then repeatedly
  take the smallest set of k still free links that, with the pairs joining them to each
  other and to the fixed links, has zero mobility 3k - 2p_k = 0 (k = 2 first: a dyad of
  class II; then k = 4: a triad of class III or a four-link contour of class IV; ...).
  The class is the number of links in the group's largest closed contour of inner pairs,
  or its largest number of inner pairs on one link (2 for a dyad); the order is its number
  of outer pairs.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _core
from ._core import ModelError, PlanardynError
from .mechanism import Mechanism, from_dict

#: Relative singular value below which a constraint counts as dependent: the core's
#: rank test (kinematics::singularity::RANK_TOL).
RANK_TOL = 1e-9
#: A pair takes part in a self-stress when its share of a unit null vector of Phi_x^T is
#: above this (the null vectors are exact to about RANK_TOL, so 1e-6 is well clear of it).
SELF_STRESS_TOL = 1e-6

#: The five types of class II dyads (outer, inner, outer pair).
DYAD_TYPES = ("RRR", "RRP", "RPR", "PRP", "RPP")

__all__ = ["AssurGroup", "Loop", "Structure", "analyse", "report"]


@dataclass(frozen=True)
class AssurGroup:
    """One Assur group (a structural group of zero mobility)."""

    #: Its links (a relative input's two bodies joined by '+').
    links: tuple[str, ...]
    #: Pairs inside the group, and pairs joining it to links assigned before it.
    inner_pairs: tuple[str, ...]
    outer_pairs: tuple[str, ...]
    #: Class (2 = dyad, 3 = triad, 4 = four-link contour, ...) and order (outer pairs).
    group_class: int
    order: int
    #: 'RRR', 'RRP', 'RPR', 'PRP', 'RPP' (R revolute, P prismatic) for a dyad, in the order
    #: outer pair, inner pair, outer pair; for a larger group its pairs' letters.
    kind: str

    @property
    def description(self) -> str:
        roman = {2: "II", 3: "III", 4: "IV", 5: "V", 6: "VI"}.get(self.group_class, str(self.group_class))
        what = {2: "dyad", 3: "triad"}.get(self.group_class, "group")
        return f"class {roman} {what} {self.kind}, order {self.order}: {', '.join(self.links)}"


@dataclass(frozen=True)
class Loop:
    """An independent loop: the pair closing it and the path around it."""

    closing_pair: str
    #: Alternating link and pair names around the loop, starting and ending at one link.
    path: tuple[str, ...]

    def __str__(self) -> str:
        return " - ".join(self.path)


@dataclass(frozen=True)
class Structure:
    """The structural analysis of a mechanism (see the module doc)."""

    name: str
    #: Mobile bodies (n) and every link including the ground.
    bodies: tuple[str, ...]
    links: tuple[str, ...]
    #: Pair names by kind ('revolute', 'prismatic').
    pairs_by_kind: dict[str, tuple[str, ...]]
    n_pairs: int
    #: Generalized coordinates and their input pairs.
    coordinates: tuple[str, ...]
    input_pairs: tuple[str, ...]
    #: Chebyshev-Grubler mobility 3n - 2p.
    grubler: int
    #: Rank of Phi_x (2p x 3n) at the drawing and its singular values (scaled, ascending).
    rank: int
    singular_values: np.ndarray
    #: 3n - rank: the true (instantaneous) mobility at the drawing.
    mobility: int
    #: 2p - rank redundant constraints and the pairs each self-stress involves.
    redundant: int
    redundant_pairs: tuple[tuple[str, ...], ...]
    #: Independent loops p - (n + 1) + 1 (connected mechanism) and a basis.
    n_loops: int
    loops: tuple[Loop, ...]
    connected: bool
    #: Input links (driven from ground) and relative inputs (two links, locked).
    input_links: tuple[str, ...]
    relative_inputs: tuple[str, ...]
    groups: tuple[AssurGroup, ...]
    #: Links no zero-mobility group took (over- or under-constrained parts).
    left_over: tuple[str, ...]
    #: 3k - 2p_k of those links with every pair that touches them (0 when none is left).
    left_over_mobility: int
    #: Type II measure at the start (None when the core refused the model or is singular).
    sigma_min: float | None
    #: The loader's message when the model cannot be built (the analysis then uses the drawing).
    load_error: str | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)


# ----------------------------------------------------------------------------- topology


@dataclass(frozen=True)
class _Pair:
    name: str
    kind: str  # 'revolute' | 'prismatic'
    a: str
    b: str
    at: str
    axis: tuple[float, float] | None  # drawn global direction, prismatic only


def _pairs_of(model: Mapping[str, Any]) -> list[_Pair]:
    pts = model["points"]
    out = []
    for pr in model["pairs"]:
        a, b = pr["bodies"]
        at = pr["at"] if "at" in pr else pr["centers"][0]  # a gear pair names its centres
        name = pr.get("name") or f"{a}-{b}@{at}"
        axis = None
        if pr["type"] == "prismatic":
            if "axis" in pr:
                axis = (float(pr["axis"][0]), float(pr["axis"][1]))
            else:
                p, q = pr["along"]
                axis = (pts[q][0] - pts[p][0], pts[q][1] - pts[p][1])
        out.append(_Pair(name, pr["type"], a, b, at, axis))
    return out


def _loops(links: Sequence[str], pairs: Sequence[_Pair]) -> tuple[list[Loop], bool]:
    """A loop basis: a BFS spanning tree from the ground; each pair outside it closes one loop."""
    adj: dict[str, list[tuple[str, _Pair]]] = {l: [] for l in links}
    for pr in pairs:
        adj[pr.a].append((pr.b, pr))
        adj[pr.b].append((pr.a, pr))
    parent: dict[str, tuple[str, _Pair] | None] = {"ground": None}
    order = ["ground"]
    tree: set[str] = set()
    for link in order:
        for other, pr in adj[link]:
            if other not in parent:
                parent[other] = (link, pr)
                tree.add(pr.name)
                order.append(other)
    connected = len(parent) == len(links)

    def to_root(l: str) -> list[str]:
        path = [l]
        while parent.get(l) is not None:
            l = parent[l][0]  # type: ignore[index]
            path.append(l)
        return path

    loops = []
    for pr in pairs:
        if pr.name in tree or pr.a not in parent or pr.b not in parent:
            continue
        pa, pb = to_root(pr.a), to_root(pr.b)
        common = next(l for l in pa if l in pb)
        up = pa[: pa.index(common) + 1]
        down = pb[: pb.index(common)][::-1]
        path: list[str] = []
        for l in up:  # pr.a ... common
            path.append(l)
            if l != common:
                path.append(parent[l][1].name)  # type: ignore[index]
        for l in down:  # below common ... pr.b
            path.append(parent[l][1].name)  # type: ignore[index]
            path.append(l)
        path += [pr.name, pr.a]
        loops.append(Loop(pr.name, tuple(path)))
    return loops, connected


def _assur(bodies: Sequence[str], pairs: Sequence[_Pair], input_pairs: Sequence[str]):
    """Lock the input pairs and split the free links into Assur groups (module doc)."""
    # Union-find of links joined by a locked input pair.
    root = {l: l for l in ["ground", *bodies]}

    def find(l: str) -> str:
        while root[l] != l:
            l = root[l]
        return l

    input_links, relative = [], []
    for pr in pairs:
        if pr.name in input_pairs:
            ra, rb = find(pr.a), find(pr.b)
            if "ground" in (pr.a, pr.b):
                input_links.append(pr.b if pr.a == "ground" else pr.a)
            else:
                relative.append(f"{pr.a}+{pr.b} ({pr.name})")
            if ra != rb:
                # Keep the ground as the root of its class.
                if rb == "ground":
                    ra, rb = rb, ra
                root[rb] = ra
    members: dict[str, list[str]] = {}
    for l in bodies:
        members.setdefault(find(l), []).append(l)
    label = {r: "+".join(ls) for r, ls in members.items()}
    free = [r for r in members if r != "ground"]
    # The pairs between locked units (a locked input pair is inside one unit).
    edges = [(find(pr.a), find(pr.b), pr) for pr in pairs if pr.name not in input_pairs]
    assigned = {"ground"}
    groups: list[AssurGroup] = []
    while True:
        left = [u for u in free if u not in assigned]
        found = None
        for k in range(2, len(left) + 1, 2):
            for subset in itertools.combinations(left, k):
                s = set(subset)
                inner = [e for e in edges if e[0] in s and e[1] in s and e[0] != e[1]]
                outer = [e for e in edges if (e[0] in s) != (e[1] in s) and (e[0] in assigned or e[1] in assigned)]
                if 3 * k != 2 * (len(inner) + len(outer)):
                    continue
                degree = {u: 0 for u in s}
                for a, b, _ in inner + outer:
                    for u in (a, b):
                        if u in degree:
                            degree[u] += 1
                if min(degree.values()) < 2 or not _connected(s, inner):
                    continue
                found = (subset, inner, outer)
                break
            if found:
                break
        if found is None:
            break
        subset, inner, outer = found
        assigned |= set(subset)
        groups.append(_group([label[u] for u in subset], subset, inner, outer))
    rest = {u for u in free if u not in assigned}
    left_over = tuple(label[u] for u in free if u in rest)
    # Grubler count of what is left: < 0 over-constrained (redundant), > 0 free to move.
    rest_mobility = 3 * len(rest) - 2 * sum(1 for a, b, _ in edges if a in rest or b in rest)
    return tuple(dict.fromkeys(input_links)), tuple(relative), tuple(groups), left_over, rest_mobility


def _connected(units: set[str], inner: list) -> bool:
    seen, todo = set(), [next(iter(units))]
    while todo:
        u = todo.pop()
        if u in seen:
            continue
        seen.add(u)
        todo += [b if a == u else a for a, b, _ in inner if u in (a, b)]
    return seen == units


def _group(names: list[str], units: tuple[str, ...], inner: list, outer: list) -> AssurGroup:
    letter = {"revolute": "R", "prismatic": "P", "gear": "G", "slot": "S"}
    k = len(units)
    if k == 2:
        u1, u2 = units
        o1 = next(pr for a, b, pr in outer if u1 in (a, b))
        o2 = next(pr for a, b, pr in outer if u2 in (a, b))
        kind = letter[o1.kind] + letter[inner[0][2].kind] + letter[o2.kind]
        # A dyad reads the same both ways (PRR is RRP): name it by the five classical types.
        kind = kind if kind in DYAD_TYPES else kind[::-1]
        cls = 2
    else:
        degree = {u: sum(u in (a, b) for a, b, _ in inner) for u in units}
        cls = max(max(degree.values()), _longest_cycle(units, inner))
        kind = "".join(sorted(letter[pr.kind] for _, _, pr in inner + outer)).replace("PR", "RP")
        kind = f"{kind.count('R')}R{kind.count('P')}P" if "P" in kind else f"{len(kind)}R"
    return AssurGroup(
        links=tuple(names),
        inner_pairs=tuple(pr.name for _, _, pr in inner),
        outer_pairs=tuple(pr.name for _, _, pr in outer),
        group_class=cls,
        order=len(outer),
        kind=kind,
    )


def _longest_cycle(units: Sequence[str], inner: list) -> int:
    """Links in the longest simple cycle of the inner-pair graph (0 for a tree); tiny graphs."""
    adj: dict[str, list[str]] = {u: [] for u in units}
    for a, b, _ in inner:
        adj[a].append(b)
        adj[b].append(a)
    best = 0

    def walk(start: str, u: str, seen: list[str]) -> None:
        nonlocal best
        for v in adj[u]:
            if v == start and len(seen) >= 3:
                best = max(best, len(seen))
            elif v not in seen:
                walk(start, v, seen + [v])

    for u in units:
        walk(u, u, [u])
    return best


# ----------------------------------------------------------------------------- the Jacobian


def _drawn_jacobian(model: Mapping[str, Any], pairs: Sequence[_Pair]) -> np.ndarray:
    """Scaled Phi_x at the drawing from the model dict alone (for a model the core refuses).

    Each body's reference point is its first point (any reference gives the same rank and
    the same null space of Phi_x^T: a change of reference is an invertible column change).
    Revolute rows: d(P_b - P_a); prismatic rows: d(phi_b - phi_a) and n . d(P_b - P_a), n the
    guide's normal. Scaled like the core's: metre rows / L, translation columns * L.
    """
    pts = {k: (float(v[0]), float(v[1])) for k, v in model["points"].items()}
    bodies = list(model["bodies"])
    col = {b: 3 * i for i, b in enumerate(bodies)}
    ref = {b: pts[model["bodies"][b]["points"][0]] for b in bodies}
    L = max((math.dist(p, q) for p, q in itertools.combinations(pts.values(), 2)), default=1.0) or 1.0
    J = np.zeros((2 * len(pairs), 3 * len(bodies)))

    def point_rows(link: str, P: tuple[float, float], sign: float) -> np.ndarray:
        g = np.zeros((2, 3 * len(bodies)))
        if link != "ground":
            c, r = col[link], ref[link]
            g[:, c : c + 2] = sign * np.eye(2) * L
            g[:, c + 2] = sign * np.array([-(P[1] - r[1]), P[0] - r[0]])
        return g

    for k, pr in enumerate(pairs):
        if pr.kind not in ("revolute", "prismatic"):
            raise ValueError(f"pair {pr.name!r}: the analysis from the drawing (for a model the loader refuses) "
                             f"knows revolute and prismatic pairs only; fix the model so that it loads")
        P = pts[pr.at]
        d = point_rows(pr.b, P, 1.0) + point_rows(pr.a, P, -1.0)
        if pr.kind == "revolute":
            J[2 * k : 2 * k + 2] = d / L
        else:
            assert pr.axis is not None
            t = np.array(pr.axis) / np.hypot(*pr.axis)
            n = np.array([-t[1], t[0]])
            for link, sign in ((pr.b, 1.0), (pr.a, -1.0)):
                if link != "ground":
                    J[2 * k, col[link] + 2] = sign
            J[2 * k + 1] = n @ d / L
    return J


def _rank_and_null(J: np.ndarray) -> tuple[int, np.ndarray, np.ndarray]:
    """Rank of J, its singular values (ascending, min(shape) of them) and an orthonormal
    basis (columns) of the null space of J^T."""
    if J.size == 0:
        return 0, np.zeros(0), np.zeros((J.shape[0], J.shape[0]))
    U, s, _ = np.linalg.svd(J)
    top = s.max() if s.size else 0.0
    rank = int(np.sum(s > RANK_TOL * max(top, 1.0)))
    return rank, np.sort(s), U[:, rank:]


def _self_stresses(
    null: np.ndarray, pairs: Sequence[_Pair], pair_rows: Sequence[tuple[int, int]] | None = None
) -> tuple[tuple[str, ...], ...]:
    """The pairs each independent self-stress involves. A basis of the null space of
    Phi_x^T is reduced (column echelon form) so that each vector involves as few pairs as
    the structure allows; each is reported with its pairs."""
    if null.shape[1] == 0:
        return ()
    # Reduced echelon form of the basis: each vector then has a pivot row the others lack.
    Q = null.copy()
    rows = []
    for j in range(Q.shape[1]):
        i = int(np.argmax(np.abs(Q[:, j:]).max(axis=1) * [r not in rows for r in range(Q.shape[0])]))
        jj = j + int(np.argmax(np.abs(Q[i, j:])))
        Q[:, [j, jj]] = Q[:, [jj, j]]
        Q[:, j] /= Q[i, j]
        for c in range(Q.shape[1]):
            if c != j:
                Q[:, c] -= Q[i, c] * Q[:, j]
        rows.append(i)
    out = []
    for j in range(Q.shape[1]):
        v = Q[:, j] / np.linalg.norm(Q[:, j])
        layout = pair_rows or [(2 * k, 2 * k + 2) for k in range(len(pairs))]
        share = [np.linalg.norm(v[start:stop]) for start, stop in layout]
        out.append(tuple(pr.name for pr, w in zip(pairs, share) if w > SELF_STRESS_TOL))
    return tuple(out)


# ----------------------------------------------------------------------------- analyse


def analyse(mech: Mechanism | Mapping[str, Any]) -> Structure:
    """Structural analysis of a mechanism, or of a model dict (then also when the loader
    refuses it, e.g. for redundant constraints: the analysis uses the drawing)."""
    load_error = None
    if isinstance(mech, Mechanism):
        model, native = mech.to_dict(), mech
    else:
        model = dict(mech)
        try:
            native = from_dict(model)
        except (ModelError, PlanardynError) as e:
            native, load_error = None, str(e)
    pairs = _pairs_of(model)
    # Each pair's rows of Phi_x (two for a drawing the loader refused: revolute, prismatic).
    pair_rows = [(2 * k, 2 * k + 2) for k in range(len(pairs))]
    if native is not None:
        # The core's names (it names unnamed pairs), row layout and Jacobian at the drawing.
        pairs = [_Pair(n, p.kind, p.a, p.b, p.at, p.axis) for n, p in zip(native.pair_names, pairs)]
        pair_rows = [pr["rows"] for pr in native.pairs]
        J = np.asarray(_core.constraint_jacobian(native._native, native.x0, True))
        bodies = tuple(native.body_names)
    else:
        J = _drawn_jacobian(model, pairs)
        bodies = tuple(model["bodies"])
    links = ("ground", *bodies)
    n, p, n_rows = len(bodies), len(pairs), J.shape[0]
    rank, sv, null = _rank_and_null(J)
    input_pairs = tuple(c["pair"] for c in model["coordinates"])
    loops, connected = _loops(links, pairs)
    input_links, relative, groups, left_over, rest_mobility = _assur(bodies, pairs, input_pairs)
    kinds: dict[str, list[str]] = {}
    for pr in pairs:
        kinds.setdefault(pr.kind, []).append(pr.name)
    sigma = None
    notes = []
    if native is not None:
        try:
            sigma = float(native.kinematics(native.q0)["sigma_min"])
        except PlanardynError as e:
            notes.append(f"type II measure not available at the start: {e}")
    return Structure(
        name=str(model.get("name", "")),
        bodies=bodies,
        links=links,
        pairs_by_kind={k: tuple(v) for k, v in kinds.items()},
        n_pairs=p,
        coordinates=tuple(c["name"] for c in model["coordinates"]),
        input_pairs=input_pairs,
        grubler=3 * n - n_rows,
        rank=rank,
        singular_values=sv,
        mobility=3 * n - rank,
        redundant=n_rows - rank,
        redundant_pairs=_self_stresses(null, pairs, pair_rows),
        n_loops=p - len(links) + 1 if connected else len(loops),
        loops=tuple(loops),
        connected=connected,
        input_links=input_links,
        relative_inputs=relative,
        groups=groups,
        left_over=left_over,
        left_over_mobility=rest_mobility,
        sigma_min=sigma,
        load_error=load_error,
        notes=tuple(notes),
    )


def report(mech: Mechanism | Mapping[str, Any]) -> str:
    """The structural analysis as text (what ``planardyn check`` prints)."""
    s = analyse(mech)
    n, p = len(s.bodies), s.n_pairs
    out = ["structure:"]
    if s.load_error:
        out.append(f"  the loader refuses this model: {s.load_error}")
        out.append("  (analysed from its drawing)")
    out.append(f"  links: {len(s.links)} (ground + {n} bodies); pairs: {p} ("
               + ", ".join(f"{len(v)} {k}" for k, v in s.pairs_by_kind.items()) + ")")
    out.append(f"  mobility: Chebyshev-Grubler 3n - 2p = 3*{n} - 2*{p} = {s.grubler}; "
               f"from the constraint Jacobian 3n - rank = {3 * n} - {s.rank} = {s.mobility}; "
               f"coordinates {len(s.coordinates)}")
    if s.singular_values.size:
        out.append(f"  singular values of the scaled Phi_x ({2 * p} x {3 * n}) at the drawing: "
                   f"smallest {s.singular_values[0]:.3g}, largest {s.singular_values[-1]:.3g}")
    if s.redundant:
        out.append(f"  redundant constraints: {s.redundant} (rank {s.rank} < 2p = {2 * p}): Grubler undercounts "
                   f"the mobility by {s.mobility - s.grubler}.")
        for k, names in enumerate(s.redundant_pairs, 1):
            out.append(f"    self-stress {k}: pairs {', '.join(names)} (their reactions are not unique: "
                       "removing one constraint of this set leaves the motion unchanged)")
    elif s.mobility != s.grubler:
        out.append("  (3n < 2p: more constraints than body coordinates)")
    else:
        out.append("  no redundant constraints (rank 2p)")
    out.append(f"  independent loops: {s.n_loops}" + ("" if s.connected else " (the mechanism is not connected)"))
    for lp in s.loops:
        out.append(f"    {lp}")
    inputs = list(s.input_links) + [f"{r} locked" for r in s.relative_inputs]
    out.append(f"  inputs: {', '.join(inputs) if inputs else 'none'} (pairs {', '.join(s.input_pairs)})")
    out.append("  Assur groups (inputs locked):")
    for g in s.groups:
        out.append(f"    {g.description}; outer pairs {', '.join(g.outer_pairs)}")
    if s.left_over:
        m = s.left_over_mobility
        what = "over-constrained: redundant" if m < 0 else "under-constrained: free to move"
        out.append(f"    not in any zero-mobility group: {', '.join(s.left_over)} "
                   f"(3k - 2p = {m}: {what})")
    if s.sigma_min is not None:
        out.append(f"  type II singularity measure at the start: sigma_min = {s.sigma_min:.4g} (0 = singular)")
    out += [f"  {note}" for note in s.notes]
    return "\n".join(out)
