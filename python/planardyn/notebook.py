"""Rich display in Jupyter: a mechanism shows itself as an inline SVG drawing with a summary,
a result as a summary table (with a drawing of its last configuration when it knows its
model), and :func:`viewer` embeds the interactive HTML viewer.

Everything here returns HTML strings; nothing needs IPython. :func:`register_display` hands
:func:`mechanism_html`, :func:`result_html` and :func:`point_motion_html` to IPython's HTML
formatter (``import planardyn`` does it inside IPython), so the model classes need not know
about notebooks. The result classes of the layers above (planned motions, sizing reports,
identifications...) show themselves: their ``_repr_html_`` is :class:`Summarized`'s, a table
of the rows they give, and their ``__repr__`` one line, never an array's contents.
"""

from __future__ import annotations

import html
import math
import sys
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .mechanism import Mechanism, from_result
from .plot import default_trace_points, pivot_points
from .result import PointMotion, SimulationResult
from .viewer import viewer_html

COLORS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"]


def mechanism_svg(
    mech: Mechanism,
    x: ArrayLike | None = None,
    *,
    width: int = 360,
    labels: bool = True,
    paths: np.ndarray | None = None,
) -> str:
    """An SVG drawing of the mechanism at body coordinates x (3n,) (default the drawing).

    Bars and plates in the bodies' colours, pairs as the core's ``pair_geometry`` gives them
    (pins circles, blocks squares, dashed guides and slots, dash-dotted pitch circles), ground
    marks, point names when ``labels``. ``paths``: optional (N, k, 2) point paths (m) drawn as thin lines. ``width`` in pixels; the height
    follows the drawing's aspect ratio.
    """
    x = mech.x0 if x is None else np.asarray(x, dtype=float)
    names = mech.point_names
    pos = mech.point_positions(x)
    L = mech.scale
    pts = pos[np.all(np.isfinite(pos), axis=1)]
    if paths is not None and np.size(paths):
        pp = np.asarray(paths).reshape(-1, 2)
        pts = np.vstack([pts, pp[np.all(np.isfinite(pp), axis=1)]])
    pad = 0.15 * L
    x0, y0 = pts.min(axis=0) - [pad, 1.6 * pad]
    x1, y1 = pts.max(axis=0) + pad
    s = width / (x1 - x0)
    height = max(60, int(math.ceil((y1 - y0) * s)))
    X = lambda v: f"{(v - x0) * s:.2f}"  # noqa: E731
    Y = lambda v: f"{(y1 - v) * s:.2f}"  # noqa: E731
    where = {n: pos[i] for i, n in enumerate(names)}
    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
        f'viewBox="0 0 {width} {height}" role="img" aria-label="{html.escape(mech.name)}" '
        f'style="background:#fff;border:1px solid #dde">'
    ]
    if paths is not None:
        for j in range(np.asarray(paths).shape[1]):
            d = " ".join(f"{X(px)},{Y(py)}" for px, py in np.asarray(paths)[:, j] if np.isfinite(px))
            out.append(f'<polyline points="{d}" fill="none" stroke="{COLORS[(j + 6) % 10]}" stroke-width="1.2" '
                       f'stroke-dasharray="3 2" opacity="0.8"/>')
    for name in pivot_points(mech):
        gx, gy = where[name]
        h = 0.04 * L
        tri = f"{X(gx)},{Y(gy)} {X(gx - h)},{Y(gy - 1.6 * h)} {X(gx + h)},{Y(gy - 1.6 * h)}"
        out.append(f'<polygon points="{tri}" fill="#eee" stroke="#555" stroke-width="1"/>')
    for b, bpts in enumerate(mech.body_points):
        xy = [where[n] for n, _ in bpts]
        col = COLORS[b % 10]
        d = " ".join(f"{X(px)},{Y(py)}" for px, py in xy)
        if len(xy) >= 3:
            out.append(f'<polygon points="{d}" fill="{col}" fill-opacity="0.3" stroke="{col}" stroke-width="4" '
                       f'stroke-linejoin="round"><title>{html.escape(mech.body_names[b])}</title></polygon>')
        else:
            out.append(f'<polyline points="{d}" fill="none" stroke="{col}" stroke-width="4" stroke-linecap="round">'
                       f'<title>{html.escape(mech.body_names[b])}</title></polyline>')
    for g in mech.pair_geometry(x):
        tip = f"<title>{html.escape(g['name'])} ({g['kind']})</title>"
        for (ax, ay), (bx, by) in g["lines"]:
            out.append(f'<line x1="{X(ax)}" y1="{Y(ay)}" x2="{X(bx)}" y2="{Y(by)}" stroke="#666" stroke-dasharray="5 4"/>')
        for (cx, cy), r in g["circles"]:
            out.append(f'<circle cx="{X(cx)}" cy="{Y(cy)}" r="{r * s:.2f}" fill="none" stroke="#555" '
                       f'stroke-dasharray="6 3 1 3">{tip}</circle>')
        for px, py in g["blocks"]:
            out.append(f'<rect x="{(px - x0) * s - 5:.2f}" y="{(y1 - py) * s - 5:.2f}" width="10" height="10" '
                       f'fill="#fff" stroke="#000">{tip}</rect>')
        for px, py in g["pins"]:
            out.append(f'<circle cx="{X(px)}" cy="{Y(py)}" r="4.5" fill="#fff" stroke="#000" stroke-width="1.3">{tip}</circle>')
    if labels:
        for name in names:
            px, py = where[name]
            if np.isfinite(px):
                out.append(f'<text x="{(px - x0) * s + 6:.2f}" y="{(y1 - py) * s - 6:.2f}" font-size="11" '
                           f'font-family="sans-serif" fill="#222">{html.escape(name)}</text>')
    out.append("</svg>")
    return "".join(out)


def _table(rows: list[tuple[str, str]]) -> str:
    """Rows of (field, HTML) as a two-column table."""
    cells = "".join(
        f'<tr><th style="text-align:left;padding-right:12px">{html.escape(k)}</th><td style="text-align:left">{v}</td></tr>'
        for k, v in rows
    )
    return f'<table style="border-collapse:collapse;font-size:13px">{cells}</table>'


def _grubler(mech: Mechanism) -> str:
    """The Chebyshev-Grubler count: 3n minus the pairs' constraint rows."""
    rows = sum(stop - start for start, stop in (p["rows"] for p in mech.pairs))
    form = "3n - 2p" if rows == 2 * len(mech.pairs) else "3n - rows"
    return f"{form} = {3 * mech.n_bodies - rows}"


def mechanism_html(mech: Mechanism) -> str:
    """The mechanism's notebook view: the drawing (SVG) beside a summary table."""
    coords = ", ".join(
        f"{html.escape(n)} = {v:.6g} {u}" for n, v, u in zip(mech.coordinate_names, mech.drawn_q, mech.coordinate_units)
    )
    kinds: dict[str, int] = {}
    for p in mech.pairs:
        kinds[p["kind"]] = kinds.get(p["kind"], 0) + 1
    rows = [
        ("model", f"<b>{html.escape(mech.name)}</b>"),
        ("source", html.escape(mech.source)),
        ("bodies", f"{mech.n_bodies}: {html.escape(', '.join(mech.body_names))}"),
        ("pairs", ", ".join(f"{v} {k}" for k, v in kinds.items())),
        ("mobility", f"{mech.dof} ({_grubler(mech)})"),
        ("coordinates (drawn)", coords),
        ("mass", f"{float(np.sum(mech.masses)):.4g} kg"),
        ("gravity", f"({mech.gravity[0]:.4g}, {mech.gravity[1]:.4g}) m/s²"),
    ]
    return (
        '<div style="display:flex;gap:16px;align-items:flex-start;flex-wrap:wrap">'
        f"{mechanism_svg(mech)}{_table(rows)}</div>"
    )


def result_html(result: SimulationResult) -> str:
    """The result's notebook view: status, span, counters and the range of every coordinate
    and drive effort; with the drawing of the last configuration and the point paths when
    the result knows its model (``result.metadata['model']``)."""
    n = len(result.t)
    st = result.stats
    ok = "#1a7f37" if result.success else "#cf222e"
    rows = [
        ("status", f'<b style="color:{ok}">{html.escape(result.status)}</b> {html.escape(result.message)}'),
        ("outputs", f"{n}" + (f", t = {result.t[0]:.6g} .. {result.t[-1]:.6g} s" if n else "")),
    ]
    if "naccept" in st:
        rows.append(("steps", f"{st.get('naccept', 0)} accepted, {st.get('nreject', 0)} rejected, "
                              f"{st.get('nfev', 0)} evaluations"))
    rows.append(("energy drift", f"{result.energy.drift:.3g} J"))
    if n:
        rows.append(("min sigma", f"{float(np.min(result.sigma)):.3g}"))
        for k, name in enumerate(result.coordinate_names):
            u = "rad" if result.coordinate_kinds[k] == "angle" else "m"
            e = "N m" if result.coordinate_kinds[k] == "angle" else "N"
            rows.append((name, f"{result.q[:, k].min():.4g} .. {result.q[:, k].max():.4g} {u}; "
                               f"tau {result.tau[:, k].min():.4g} .. {result.tau[:, k].max():.4g} {e}"))
    drawing = ""
    if n and result.metadata.get("model"):
        try:
            mech = from_result(result)
            idx = [mech.point_names.index(p) for p in default_trace_points(mech)]
            keep = np.unique(np.linspace(0, n - 1, min(n, 300)).round().astype(int))
            paths = mech.point_positions(result.x[keep])[:, idx, :]
            drawing = mechanism_svg(mech, result.x[-1], width=300, paths=paths)
        except Exception:  # a drawing is a bonus: never fail the display
            drawing = ""
    return (
        '<div style="display:flex;gap:16px;align-items:flex-start;flex-wrap:wrap">'
        f"{drawing}{_table(rows)}</div>"
    )


def grid(header: list[str], rows: list[list[str]]) -> str:
    """A table with a header row; every cell is text (escaped here)."""
    cell = 'style="text-align:right;padding:0 8px"'
    head = "".join(f"<th {cell}>{html.escape(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td {cell}>{html.escape(v)}</td>" for v in r) + "</tr>" for r in rows)
    return f'<table style="border-collapse:collapse;font-size:13px;margin-top:6px"><tr>{head}</tr>{body}</table>'


def per_coordinate(names: list[str], values: Any, units: list[str]) -> str:
    """``"theta1 1.23 N m, theta2 0.456 N m"``: a value (4 digits) and its unit per name."""
    return ", ".join(f"{n} {v:.4g} {u}" for n, v, u in zip(names, np.ravel(values), units))


def peak_rows(mech: Mechanism, tau: Any, qd: Any) -> list[tuple[str, str]]:
    """The rows "peak |tau|" and "peak |qd|" of a motion's efforts and rates (N, m), each
    coordinate's largest magnitude in its unit."""
    names = mech.coordinate_names
    return [("peak |tau|", per_coordinate(names, np.abs(tau).max(axis=0), mech.effort_units)),
            ("peak |qd|", per_coordinate(names, np.abs(qd).max(axis=0), [f"{u}/s" for u in mech.coordinate_units]))]


class Summarized:
    """What the result classes share for a notebook: ``_repr_html_`` shows the class's name
    over a table of the rows :meth:`_summary_rows` gives ((field, text), escaped here) and the
    tables :meth:`_summary_tables` gives (a header and rows of texts). Their ``__repr__`` is
    their own: one line, no array's contents."""

    def _summary_rows(self) -> list[tuple[str, str]]:
        raise NotImplementedError

    def _summary_tables(self) -> list[tuple[list[str], list[list[str]]]]:
        return []

    def _repr_html_(self) -> str:
        rows = [(k, html.escape(v)) for k, v in self._summary_rows()]
        tables = "".join(grid(header, body) for header, body in self._summary_tables())
        return f"<div><b>{html.escape(type(self).__name__)}</b>{_table(rows)}{tables}</div>"


def point_motion_html(motion: PointMotion) -> str:
    """A point motion's notebook view: its span, and per point its travel in x and y and its
    largest speed and acceleration (:meth:`PointMotion.describe`)."""
    n = len(motion.t)
    rows = [("outputs", f"{n}" + (f", t = {motion.t[0]:.6g} .. {motion.t[-1]:.6g} s" if n else ""))]
    rows += [(name, html.escape(motion.describe(name).removeprefix(f"{name}: "))) for name in motion.names]
    return f"<div><b>PointMotion</b>{_table(rows)}</div>"


class Viewer:
    """The interactive viewer in a notebook cell (an iframe whose page is inline)."""

    def __init__(self, page: str, height: int = 640) -> None:
        self.page, self.height = page, height

    def _repr_html_(self) -> str:
        return (
            f'<iframe srcdoc="{html.escape(self.page, quote=True)}" '
            f'style="width:100%;height:{self.height}px;border:0" sandbox="allow-scripts"></iframe>'
        )

    def save(self, path: Any) -> None:
        """Write the page to a file."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.page)


def viewer(mech: Mechanism | None, result: SimulationResult, height: int = 640, **kw: Any) -> Viewer:
    """The HTML viewer for a notebook cell: ``planardyn.notebook.viewer(mech, res)`` as the
    cell's last line. ``mech`` None: the result's own model. ``kw`` go to
    :func:`planardyn.viewer.viewer_html`."""
    if mech is None:
        mech = from_result(result)
    return Viewer(viewer_html(mech, result, **kw), height)


def register_display(shell: Any = None) -> bool:
    """Show every :class:`~planardyn.Mechanism`, :class:`~planardyn.SimulationResult` and
    :class:`~planardyn.PointMotion` as HTML (:func:`mechanism_html`, :func:`result_html`,
    :func:`point_motion_html`) in an IPython shell (default: the
    running one, if any). Returns whether there was a shell to register with."""
    if shell is None:
        ipython = sys.modules.get("IPython")  # not imported here: only a running shell matters
        shell = ipython.get_ipython() if ipython is not None else None
    if shell is None:
        return False
    formatter = shell.display_formatter.formatters["text/html"]
    formatter.for_type(Mechanism, mechanism_html)
    formatter.for_type(SimulationResult, result_html)
    formatter.for_type(PointMotion, point_motion_html)
    return True
