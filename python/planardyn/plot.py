"""Matplotlib helpers. Each takes ``ax=`` (a new figure is made only when it is None) and
returns the artists it drew. Nothing here changes rcParams or calls ``plt.show()``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from .arguments import error

if TYPE_CHECKING:
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes

    from .mechanism import Mechanism
    from .result import PointMotion, SimulationResult

#: Units of a coordinate's quantities by its kind: value, rate, acceleration, drive effort.
UNITS = {
    "angle": {"q": "rad", "qd": "rad/s", "qdd": "rad/s^2", "tau": "N m"},
    "displacement": {"q": "m", "qd": "m/s", "qdd": "m/s^2", "tau": "N"},
}


def units(result: SimulationResult, quantity: str) -> list[str]:
    """The unit of ``quantity`` (``'q'``, ``'qd'``, ``'qdd'``, ``'tau'``) of each coordinate."""
    return [UNITS[kind][quantity] for kind in result.coordinate_kinds]


def axis_label(what: str, names: Sequence[str], unit_of: Sequence[str]) -> str:
    """An axis label with each coordinate's unit: ``"drive effort (N m)"`` when all share one,
    else ``"drive effort: theta (N m), s (N)"``."""
    if len(set(unit_of)) <= 1:
        return f"{what} ({unit_of[0]})" if unit_of else what
    return f"{what}: " + ", ".join(f"{n} ({u})" for n, u in zip(names, unit_of))


def _axes(ax: Axes | None) -> Axes:
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    _, ax = plt.subplots()
    return ax


def plot_coordinates(
    result: SimulationResult, ax: Axes | None = None, which: str = "q", **line_kw: Any
) -> list[Artist]:
    """Coordinates (``which='q'``), rates (``'qd'``) or accelerations (``'qdd'``) against time.

    Returns the lines, one per coordinate.
    """
    ax = _axes(ax)
    if which not in ("q", "qd", "qdd"):
        raise ValueError(f"which must be 'q', 'qd' or 'qdd', got {which!r}")
    data = getattr(result, which)
    lines: list[Artist] = []
    labels = [name if which == "q" else f"{which}_{name}" for name in result.coordinate_names]
    for k, label in enumerate(labels):
        lines += ax.plot(result.t, data[:, k], label=label, **line_kw)
    ax.set_xlabel("t (s)")
    ax.set_ylabel(axis_label(which, labels, units(result, which)))
    ax.legend(loc="best")
    ax.grid(True, alpha=0.3)
    return lines


def plot_efforts(result: SimulationResult, ax: Axes | None = None, **line_kw: Any) -> list[Artist]:
    """Drive efforts tau against time (N m on angles, N on displacements). Returns the lines."""
    ax = _axes(ax)
    lines: list[Artist] = []
    for k, name in enumerate(result.coordinate_names):
        lines += ax.plot(result.t, result.tau[:, k], label=f"tau_{name}", **line_kw)
    ax.set_xlabel("t (s)")
    ax.set_ylabel(axis_label("drive effort", [f"tau_{n}" for n in result.coordinate_names], units(result, "tau")))
    ax.legend(loc="best")
    ax.grid(True, alpha=0.3)
    return lines


def plot_energy(result: SimulationResult, ax: Axes | None = None, balance: bool = True) -> list[Artist]:
    """Kinetic T, potential V, total T + V and work W of the non-conservative forces (J).

    With ``balance=True`` a second y axis shows, for a simulation, the energy balance
    T + V - W - E0 (the integration error); for inverse dynamics (``metadata["kind"] ==
    "inverse"``, W the work of the drive efforts only), W - (T + V - E0): the energy the
    model's dampers, friction and other non-conservative loads took. Returns the lines.
    """
    ax = _axes(ax)
    e = result.energy
    inverse = result.metadata.get("kind") == "inverse"
    lines: list[Artist] = []
    lines += ax.plot(result.t, e.kinetic, label="kinetic T")
    lines += ax.plot(result.t, e.potential, label="potential V")
    lines += ax.plot(result.t, e.total, label="total T + V", linewidth=2)
    lines += ax.plot(result.t, e.work, label="work W of the drives" if inverse else "work W", linestyle="--")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("energy (J)")
    ax.grid(True, alpha=0.3)
    handles = list(lines)
    if balance:
        ax2 = ax.twinx()
        if inverse:
            bal = ax2.plot(result.t, -e.balance, color="k", linewidth=0.8,
                           label="taken by dampers, friction, loads: W - (T + V - E0)")
            ax2.set_ylabel("energy dissipated (J)")
        else:
            bal = ax2.plot(result.t, e.balance, color="k", linewidth=0.8, label="balance T + V - W - E0")
            ax2.set_ylabel("energy balance (J)")
        lines += bal
        handles += bal
    # Below the axes: a legend inside would cover a curve, and matplotlib's loc="best" only
    # avoids the lines of the axes it belongs to, not the balance on the twin axes.
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=3, fontsize="small",
              frameon=False)
    return lines


def draw_mechanism(
    mech: Mechanism,
    x: ArrayLike | None = None,
    ax: Axes | None = None,
    *,
    labels: bool = True,
    color: Any = None,
    alpha: float = 1.0,
) -> list[Artist]:
    """Draw the mechanism at body coordinates x (3n,) (default: the drawing ``mech.x0``).

    Bodies with two points are bars, with more points filled polygons; ground points are
    hatched triangles; the pairs as the core's :meth:`Mechanism.pair_geometry` gives them: pins
    circles, sliding blocks squares, guides, slots and racks dashed lines, gears' pitch
    circles dash-dotted; points are
    labelled with their names when ``labels``. Sets an equal aspect ratio. Returns the artists.
    """
    from matplotlib.patches import Circle, Polygon

    ax = _axes(ax)
    x = mech.x0 if x is None else np.asarray(x, dtype=float)
    names = mech.point_names
    pos = mech.point_positions(x)
    where = {n: pos[i] for i, n in enumerate(names)}
    artists: list[Artist] = []
    colors = [f"C{i % 10}" for i in range(mech.n_bodies)] if color is None else [color] * mech.n_bodies
    for b, pts in enumerate(mech.body_points):
        xy = np.array([where[n] for n, _ in pts])
        if len(xy) >= 3:
            poly = Polygon(xy, closed=True, facecolor=colors[b], edgecolor=colors[b], alpha=0.35 * alpha, linewidth=2)
            ax.add_patch(poly)
            artists.append(poly)
        artists += ax.plot(xy[:, 0], xy[:, 1], "-", color=colors[b], linewidth=3, alpha=alpha, solid_capstyle="round")
    scale = mech.scale
    for name in pivot_points(mech):
        px, py = where[name]
        s = 0.04 * scale
        tri = Polygon(
            [[px, py], [px - s, py - 1.6 * s], [px + s, py - 1.6 * s]],
            closed=True, facecolor="none", edgecolor="0.3", hatch="////", alpha=alpha,
        )
        ax.add_patch(tri)
        artists.append(tri)
    for g in mech.pair_geometry(x):
        for (x0, y0), (x1, y1) in g["lines"]:
            artists += ax.plot([x0, x1], [y0, y1], "--", color="0.4", alpha=alpha, linewidth=1)
        for (cx, cy), r in g["circles"]:
            circle = Circle((cx, cy), r, fill=False, edgecolor="0.3", linestyle="-.", linewidth=1, alpha=alpha)
            ax.add_patch(circle)
            artists.append(circle)
        for px, py in g["blocks"]:
            artists += ax.plot([px], [py], "s", markersize=8, markerfacecolor="white", markeredgecolor="k", alpha=alpha)
        for px, py in g["pins"]:
            artists += ax.plot([px], [py], "o", markersize=7, markerfacecolor="white", markeredgecolor="k", alpha=alpha, zorder=3)
    if labels:
        for name in names:
            px, py = where[name]
            if np.isfinite(px):
                artists.append(ax.annotate(name, (px, py), textcoords="offset points", xytext=(5, 5), fontsize=8, alpha=alpha))
    ax.set_aspect("equal")
    return artists


def pivot_points(mech: Mechanism) -> list[str]:
    """The ground points drawn with the ground mark: where a body is held to the ground, by a
    pair (a pin, a gear's axle) or a load's end (a spring's anchor). A point the ground carries
    only to lay a guide (a prismatic or slot pair's point or the ends of its ``along``) or as
    a reference of the drawing is not a pivot: the guide is drawn as its line."""
    model = mech.to_dict()
    held: set[str] = set()
    for pair in model.get("pairs", []):
        if "ground" not in pair.get("bodies", ()) or pair.get("type") in ("prismatic", "slot"):
            continue
        held.update([pair["at"]] if "at" in pair else pair.get("centers", []))
    for load in model.get("loads", []):
        held.update(point for body, point in load.get("between", []) if body == "ground")
    return [p for p in mech.ground_points if p in held]


def _nearest(t: np.ndarray, time: float) -> int:
    """Index of the output nearest to ``time`` (s)."""
    if len(t) == 0:
        raise ValueError("the result has no output")
    return int(np.argmin(np.abs(np.asarray(t) - time)))


def default_trace_points(mech: Mechanism) -> list[str]:
    """The points worth tracing: those not on the ground, carried by two or more bodies
    (joints of the loop, the end effector of a parallel robot) or by a body with 3+ points
    (coupler points); if none, every point not on the ground."""
    ground = set(mech.ground_points)
    carriers: dict[str, int] = {}
    coupler: set[str] = set()
    for pts in mech.body_points:
        for name, _ in pts:
            carriers[name] = carriers.get(name, 0) + 1
            if len(pts) >= 3:
                coupler.add(name)
    # The points of the pairs of mobile bodies only (a point between two moving links).
    mobile_joints = {p["point"] for p in mech.pairs if "ground" not in p["bodies"]}
    chosen = [n for n in mech.point_names if n not in ground and (n in coupler or n in mobile_joints)]
    # Prefer the points carried by the most bodies (an end effector) when there are many.
    if len(chosen) > 3:
        chosen = sorted(chosen, key=lambda n: -carriers.get(n, 0))[:3]
        chosen = [n for n in mech.point_names if n in chosen]
    return chosen or [n for n in mech.point_names if n not in ground]


def trace_points(mech: Mechanism, points: Sequence[str] | None) -> list[str]:
    """The points whose paths to draw: ``points`` (default :func:`default_trace_points`),
    each a named point of the model, else an ArgumentError (argument ``traces``) listing them."""
    points = default_trace_points(mech) if points is None else list(points)
    unknown = [p for p in points if p not in mech.point_names]
    if unknown:
        raise error("traces", f"unknown point(s) {', '.join(unknown)}; the model has {', '.join(mech.point_names)}")
    return points


def plot_point_paths(
    mech: Mechanism,
    result: SimulationResult,
    points: list[str] | None = None,
    ax: Axes | None = None,
    **line_kw: Any,
) -> list[Artist]:
    """Paths of named points over the whole result (coupler curves, end-effector path), in m.

    ``points``: names (default :func:`default_trace_points`). Returns the lines, one a point.
    """
    ax = _axes(ax)
    points = trace_points(mech, points)
    pos = mech.point_positions(result.x)  # (N, P, 2)
    lines: list[Artist] = []
    for name in points:
        i = mech.point_names.index(name)
        kw = {"linewidth": 1.2, "alpha": 0.8, **line_kw}
        lines += ax.plot(pos[:, i, 0], pos[:, i, 1], label=f"path of {name}", **kw)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    ax.legend(loc="best", fontsize="small")
    return lines


def draw_mechanism_at(
    mech: Mechanism,
    result: SimulationResult,
    time: float,
    ax: Axes | None = None,
    *,
    labels: bool = True,
    paths: bool | list[str] = True,
) -> list[Artist]:
    """The mechanism at the output nearest to ``time`` (s), labelled, with the point paths
    (``paths=True``: :func:`default_trace_points`, or a list of names) and a title giving the
    time. Returns the artists."""
    ax = _axes(ax)
    k = _nearest(result.t, time)
    artists: list[Artist] = []
    if paths:
        artists += plot_point_paths(mech, result, None if paths is True else paths, ax=ax, linestyle=":")
    artists += draw_mechanism(mech, result.x[k], ax=ax, labels=labels)
    artists.append(ax.set_title(f"{mech.name}, t = {result.t[k]:.4g} s"))
    if paths:
        ax.legend(loc="best", fontsize="small")
    return artists


def plot_reaction(mech: Mechanism, result: SimulationResult, pair: str, fig: Any = None) -> list[Artist]:
    """The force of one pair along a run: its magnitude against time, and a polar diagram of
    the force on the pair's second body in that body's frame (the load a pin or bearing
    sees as the body turns; in the world frame when the second body is the ground).

    ``fig`` is a matplotlib figure to draw in (a new one when None). Returns the artists.
    """
    if pair not in mech.pair_names:
        raise error("pair", f"no pair {pair!r}; the pairs are {', '.join(mech.pair_names)}")
    k = mech.pair_names.index(pair)
    force = mech.reactions(result)[:, k, :2]
    second = mech.pairs[k]["bodies"][1]
    phi = result.poses[:, mech.body_names.index(second), 2] if second != "ground" else np.zeros(len(result.t))
    magnitude = np.hypot(force[:, 0], force[:, 1])
    if fig is None:
        import matplotlib.pyplot as plt

        fig = plt.figure(figsize=(10, 4))
    left, right = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2, projection="polar")
    artists: list[Artist] = left.plot(result.t, magnitude)
    left.set_xlabel("t (s)")
    left.set_ylabel(f"|F| at {pair} (N)")
    left.grid(True, alpha=0.3)
    artists += right.plot(np.arctan2(force[:, 1], force[:, 0]) - phi, magnitude)
    right.set_title(f"force on {second} at {pair}, in its frame (N)", fontsize="medium")
    return artists


def plot_torque_speed(result: SimulationResult, ax: Axes | None = None, **line_kw: Any) -> list[Artist]:
    """Drive effort against speed of each coordinate (tau_k vs qd_k): the operating points a
    motor must reach, start marked with a circle. Returns the lines."""
    ax = _axes(ax)
    lines: list[Artist] = []
    for k, name in enumerate(result.coordinate_names):
        (line,) = ax.plot(result.qd[:, k], result.tau[:, k], label=f"{name}", **line_kw)
        lines.append(line)
        if len(result.t):
            lines += ax.plot(result.qd[:1, k], result.tau[:1, k], "o", color=line.get_color())
    ax.set_xlabel(axis_label("speed", result.coordinate_names, units(result, "qd")))
    ax.set_ylabel(axis_label("drive effort", result.coordinate_names, units(result, "tau")))
    ax.axhline(0, color="0.6", linewidth=0.6)
    ax.axvline(0, color="0.6", linewidth=0.6)
    ax.legend(loc="best")
    ax.grid(True, alpha=0.3)
    return lines


def plot_point_motion(motion: PointMotion, points: Sequence[str] | None = None, fig: Any = None) -> list[Artist]:
    """Position, velocity and acceleration of named points against time (m, m/s, m/s^2), on
    three axes sharing t: x solid, y dashed, one colour a point (a ram's stroke, an end
    effector's path). ``points``: names of ``motion.names`` (default: all). ``fig``: a
    matplotlib Figure (default a new one, 9 x 8 in). Returns the lines."""
    names = list(motion.names) if points is None else list(points)
    unknown = [p for p in names if p not in motion.names]
    if unknown:
        raise error("points", f"no point {', '.join(unknown)} in the motion; its points are {', '.join(motion.names)}")
    if fig is None:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(9, 8))
    axes = fig.subplots(3, 1, sharex=True)
    lines: list[Artist] = []
    for ax, (what, unit) in zip(axes, (("position", "m"), ("velocity", "m/s"), ("acceleration", "m/s^2"))):
        for c, name in enumerate(names):
            value = getattr(motion, what)[:, motion.names.index(name)]
            for j, (axis, style) in enumerate((("x", "-"), ("y", "--"))):
                lines += ax.plot(motion.t, value[:, j], style, color=f"C{c % 10}", label=f"{name} {axis}")
        ax.set_ylabel(f"{what} ({unit})")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize="small")
    axes[-1].set_xlabel("t (s)")
    fig.suptitle(f"motion of {', '.join(names)}")
    fig.tight_layout()
    return lines


def plot_results(result: SimulationResult, fig: Any = None) -> list[Artist]:
    """The four time histories on one figure (2 x 2): coordinates, rates, drive efforts and
    energy. ``fig``: a matplotlib Figure (default: a new one, 11 x 7 in). Returns the lines."""
    if fig is None:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(11, 7))
    axes = fig.subplots(2, 2, sharex=True)
    artists: list[Artist] = []
    artists += plot_coordinates(result, ax=axes[0, 0])
    artists += plot_coordinates(result, ax=axes[0, 1], which="qd")
    artists += plot_efforts(result, ax=axes[1, 0])
    artists += plot_energy(result, ax=axes[1, 1])
    axes[0, 0].set_title("coordinates")
    axes[0, 1].set_title("rates")
    axes[1, 0].set_title("drive efforts")
    kind = result.metadata.get("kind", "simulation")
    if kind == "inverse":
        axes[1, 1].set_title("energy: the drives' work W, and what the loads dissipate")
    else:
        axes[1, 1].set_title(f"energy (balance drift {result.energy.drift:.2g} J)")
    for ax in axes[0]:
        ax.set_xlabel("")
    name = (result.metadata.get("model") or {}).get("name")
    fig.suptitle(f"{name or 'result'}: {kind}, {result.status}")
    fig.tight_layout()
    return artists
