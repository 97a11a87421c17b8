"""The mechanism's drawing as a file for CAD and documents: SVG, the figure of
:func:`planardyn.plot.draw_mechanism` (matplotlib's SVG, its labels as text), or DXF (ezdxf,
the ``cad`` extra) in millimetres on four layers: ``BODIES`` (a line for a bar, a closed
polyline through a link's points), ``PAIRS`` (pins and pitch circles as circles, sliding
blocks as squares, guides, slots and racks as lines), ``GROUND`` (a triangle under each pivot)
and ``LABELS`` (the points' names). ``planardyn draw MODEL -o drawing.svg|drawing.dxf`` is
the command line's face of :func:`write_drawing`.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from . import extras
from .arguments import error
from .mechanism import Mechanism
from .plot import draw_mechanism, pivot_points

#: A DXF drawing is in millimetres ($INSUNITS 4), the unit of mechanical CAD; the model's metres times this.
MM_PER_M = 1000.0
#: Sizes of the DXF symbols as fractions of the mechanism's size (``Mechanism.scale``, m), those of the plot's.
PIN_RADIUS, BLOCK_HALF, GROUND_HALF, TEXT_HEIGHT = 0.015, 0.025, 0.04, 0.03

__all__ = ["to_dxf", "to_svg", "write_drawing"]


def write_drawing(mech: Mechanism, path: str | os.PathLike[str], x: ArrayLike | None = None) -> Path:
    """Write the drawing of ``mech`` at body coordinates ``x`` (3n,) (default: as drawn,
    ``mech.x0``) to ``path``: SVG for ``.svg``, DXF for ``.dxf``. Returns the path."""
    suffix = Path(path).suffix.lower()
    if suffix == ".svg":
        return to_svg(mech, path, x)
    if suffix == ".dxf":
        return to_dxf(mech, path, x)
    raise error("path", f"{os.fspath(path)!r}: a drawing is written as SVG or DXF; give a file ending in .svg or .dxf")


def to_svg(mech: Mechanism, path: str | os.PathLike[str], x: ArrayLike | None = None) -> Path:
    """The drawing as SVG (the figure of :func:`~planardyn.plot.draw_mechanism`, its labels as
    ``<text>`` elements; no date and fixed ids, so that one drawing gives one file). Returns the path."""
    import matplotlib
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6, 5))
    ax = fig.add_subplot()
    draw_mechanism(mech, x, ax)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(mech.name)
    with matplotlib.rc_context({"svg.fonttype": "none", "svg.hashsalt": "planardyn"}):
        fig.savefig(path, format="svg", bbox_inches="tight", metadata={"Date": None})
    return Path(path)


def to_dxf(mech: Mechanism, path: str | os.PathLike[str], x: ArrayLike | None = None) -> Path:
    """The drawing as DXF (R2010), in millimetres, on the layers BODIES, PAIRS, GROUND and
    LABELS. Needs ezdxf (the ``cad`` extra). Returns the path."""
    try:
        import ezdxf
    except ImportError as e:
        raise extras.missing("cad", "a DXF drawing", e) from e
    x = mech.x0 if x is None else np.asarray(x, dtype=float)
    pos = mech.point_positions(x) * MM_PER_M
    where = {n: (float(p[0]), float(p[1])) for n, p in zip(mech.point_names, pos)}
    size = mech.scale * MM_PER_M
    doc = ezdxf.new("R2010", setup=True)
    doc.units = ezdxf.units.MM
    for layer, color in (("BODIES", 5), ("PAIRS", 1), ("GROUND", 8), ("LABELS", 7)):
        doc.layers.add(layer, color=color)
    msp = doc.modelspace()

    def on(layer: str) -> dict[str, Any]:
        return {"layer": layer}

    for pts in mech.body_points:
        xy = [where[n] for n, _ in pts]
        if len(xy) == 2:
            msp.add_line(xy[0], xy[1], dxfattribs=on("BODIES"))
        elif len(xy) > 2:
            msp.add_lwpolyline(xy, close=True, dxfattribs=on("BODIES"))
    for g in mech.pair_geometry(x):
        for a, b in g["lines"]:
            msp.add_line(_mm(a), _mm(b), dxfattribs=on("PAIRS"))
        for c, r in g["circles"]:
            msp.add_circle(_mm(c), r * MM_PER_M, dxfattribs=on("PAIRS"))
        for p in g["pins"]:
            msp.add_circle(_mm(p), PIN_RADIUS * size, dxfattribs=on("PAIRS"))
        for p in g["blocks"]:
            cx, cy = _mm(p)
            h = BLOCK_HALF * size
            msp.add_lwpolyline([(cx - h, cy - h), (cx + h, cy - h), (cx + h, cy + h), (cx - h, cy + h)], close=True,
                               dxfattribs=on("PAIRS"))
    for name in pivot_points(mech):
        px, py = where[name]
        s = GROUND_HALF * size
        msp.add_lwpolyline([(px, py), (px - s, py - 1.6 * s), (px + s, py - 1.6 * s)], close=True,
                           dxfattribs=on("GROUND"))
    for name, (px, py) in where.items():
        msp.add_text(name, height=TEXT_HEIGHT * size, dxfattribs=on("LABELS")).set_placement((px, py))
    doc.saveas(os.fspath(path))
    return Path(path)


def _mm(p: Sequence[float]) -> tuple[float, float]:
    return (float(p[0]) * MM_PER_M, float(p[1]) * MM_PER_M)
