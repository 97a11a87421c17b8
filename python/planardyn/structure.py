"""Structural analysis of a mechanism: links and pairs, mobility, loops, Assur groups.

``analyse(mech) -> Structure`` and ``report(mech) -> str`` (printed by ``planardyn check``):
the report of the core's analysis (``planardyn::structure``, see ``docs/structure.md``).
Notation: n mobile bodies (links, the ground not counted), p pairs, m coordinates.

- **Mobility** two ways: Chebyshev-Grubler-Kutzbach 3n - 2p (counts constraints), and
  3n - rank(Phi_x) from the pair-constraint Jacobian at the drawing (counts *independent*
  constraints). They differ by the number of redundant constraints 2p - rank; the pairs
  involved are those carrying a self-stress: a vector lambda != 0 with Phi_x^T lambda = 0,
  reactions in equilibrium without any load (so the reactions are not unique).
- **Loops**: p - (n + 1) + 1 independent loops for a connected mechanism; a basis from the
  pairs outside a spanning tree of the body-pair graph.
- **Assur groups**: lock the input pairs (a link driven from ground becomes part of the
  fixed frame; the two links of a relative input become one rigid link); the groups are the
  blocks of the block-triangular form of the position Jacobian, each a set of k links of
  zero mobility with the pairs joining it to the links before it (a dyad of class II, a
  triad of class III, a four-link contour of class IV...). The class is the number of links
  in the group's largest closed contour of inner pairs, or its largest number of inner pairs
  on one link (2 for a dyad); the order is its number of outer pairs.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._core import ModelError, PlanardynError, structure_of_model
from ._core import structure as native_structure
from .mechanism import Mechanism, _json_default, from_dict

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
    #: outer pair, inner pair, outer pair; for a larger group the count of each letter ('6R').
    kind: str
    #: 'class III triad 6R, order 3: distal1, distal2, distal3, platform'.
    description: str


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
    #: Pair names by kind ('revolute', 'prismatic', 'gear', 'slot').
    pairs_by_kind: dict[str, tuple[str, ...]]
    n_pairs: int
    #: Pair-constraint rows in all (two per revolute or prismatic pair, one per gear or slot).
    n_pair_rows: int
    #: Generalized coordinates and their input pairs.
    coordinates: tuple[str, ...]
    input_pairs: tuple[str, ...]
    #: Chebyshev-Grubler mobility 3n - 2p (3n less the pair rows).
    grubler: int
    #: Rank of Phi_x (pair rows x 3n) at the drawing and its singular values (scaled, ascending).
    rank: int
    singular_values: np.ndarray
    #: 3n - rank: the true (instantaneous) mobility at the drawing.
    mobility: int
    #: Pair rows - rank redundant constraints and the pairs each self-stress involves.
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
    #: Degree of actuation: the coordinates and the redundant actuators on other pairs; more
    #: than the mobility is redundant actuation (internal forces, preload: docs/actuators.md).
    actuation: int = 0


def analyse(mech: Mechanism | Mapping[str, Any]) -> Structure:
    """Structural analysis of a mechanism, or of a model dict (then also when the loader
    refuses it for its mobility, e.g. for a coordinate too many: the analysis uses the
    drawing; a dict with other errors raises the loader's ``ModelError``)."""
    load_error = None
    native: Mechanism | None
    if isinstance(mech, Mechanism):
        model, native = mech.to_dict(), mech
        core = native_structure(mech._native)
    else:
        model = dict(mech)
        try:
            native = from_dict(model)
            core = native_structure(native._native)
        except (ModelError, PlanardynError) as e:
            native, load_error = None, str(e)
            core = structure_of_model(json.dumps(model, default=_json_default, allow_nan=True))
    pair_bodies = {name: pr["bodies"] for name, pr in zip(core["pairs"], model["pairs"])}
    kinds: dict[str, list[str]] = {}
    for name, pr in zip(core["pairs"], model["pairs"]):
        kinds.setdefault(pr["type"], []).append(name)
    sigma = None
    notes = []
    if native is not None:
        try:
            sigma = float(native.kinematics(native.q0)["sigma_min"])
        except PlanardynError as e:
            notes.append(f"type II measure not available at the start: {e}")
    bodies = tuple(core["bodies"])
    return Structure(
        name=str(model.get("name", "")),
        bodies=bodies,
        links=("ground", *bodies),
        pairs_by_kind={k: tuple(v) for k, v in kinds.items()},
        n_pairs=len(core["pairs"]),
        n_pair_rows=core["n_pair_rows"],
        coordinates=tuple(c["name"] for c in model["coordinates"]),
        input_pairs=tuple(c["pair"] for c in model["coordinates"]),
        grubler=core["grubler"],
        rank=core["rank"],
        singular_values=core["singular_values"],
        mobility=core["mobility"],
        redundant=core["redundant"],
        redundant_pairs=tuple(tuple(st["pairs"]) for st in core["self_stresses"]),
        n_loops=len(core["loops"]),
        loops=tuple(Loop(lp["closing_pair"], tuple(lp["path"])) for lp in core["loops"]),
        connected=core["connected"],
        input_links=tuple(core["input_links"]),
        relative_inputs=tuple(f"{'+'.join(pair_bodies[k])} ({k})" for k in core["relative_inputs"]),
        groups=tuple(
            AssurGroup(
                links=tuple(g["links"]),
                inner_pairs=tuple(g["inner_pairs"]),
                outer_pairs=tuple(g["outer_pairs"]),
                group_class=g["class"],
                order=g["order"],
                kind=g["kind"],
                description=g["description"],
            )
            for g in core["groups"]
        ),
        left_over=tuple(core["left_over"]),
        left_over_mobility=core["left_over_mobility"],
        sigma_min=sigma,
        load_error=load_error,
        notes=tuple(notes),
        actuation=core["actuation"],
    )


def grubler_formula(s: Structure) -> str:
    """The Chebyshev-Grubler count written out: '3n - 2p = 3*4 - 2*5 = 2'."""
    n, p, rows = len(s.bodies), s.n_pairs, s.n_pair_rows
    if rows == 2 * p:
        return f"3n - 2p = 3*{n} - 2*{p} = {s.grubler}"
    return f"3n - (pair rows) = 3*{n} - {rows} = {s.grubler}"


def report(mech: Mechanism | Mapping[str, Any] | Structure) -> str:
    """The structural analysis as text (what ``planardyn check`` prints)."""
    s = mech if isinstance(mech, Structure) else analyse(mech)
    n, p, rows = len(s.bodies), s.n_pairs, s.n_pair_rows
    out = ["structure:"]
    if s.load_error:
        out.append(f"  the loader refuses this model: {s.load_error}")
        out.append("  (analysed from its drawing)")
    out.append(f"  links: {len(s.links)} (ground + {n} bodies); pairs: {p} ("
               + ", ".join(f"{len(v)} {k}" for k, v in s.pairs_by_kind.items()) + ")")
    out.append(f"  mobility: Chebyshev-Grubler {grubler_formula(s)}; "
               f"from the constraint Jacobian 3n - rank = {3 * n} - {s.rank} = {s.mobility}; "
               f"coordinates {len(s.coordinates)}")
    if s.actuation > len(s.coordinates):
        out.append(f"  actuation: {s.actuation} actuators ({len(s.coordinates)} coordinates + "
                   f"{s.actuation - len(s.coordinates)} on other pairs) for mobility {s.mobility}: redundantly "
                   f"actuated, {s.actuation - s.mobility} internal force(s)")
    if s.singular_values.size:
        out.append(f"  singular values of the scaled Phi_x ({rows} x {3 * n}) at the drawing: "
                   f"smallest {s.singular_values[0]:.3g}, largest {s.singular_values[-1]:.3g}")
    if s.redundant:
        out.append(f"  redundant constraints: {s.redundant} (rank {s.rank} < {rows} pair rows): Grubler "
                   f"undercounts the mobility by {s.mobility - s.grubler}.")
        for k, names in enumerate(s.redundant_pairs, 1):
            out.append(f"    self-stress {k}: pairs {', '.join(names)} (their reactions are not unique: "
                       "removing one constraint of this set leaves the motion unchanged)")
    elif s.mobility != s.grubler:
        out.append("  (3n < pair rows: more constraints than body coordinates)")
    else:
        out.append(f"  no redundant constraints (rank = {rows} pair rows)")
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
