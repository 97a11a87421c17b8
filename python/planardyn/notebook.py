"""Rich display in Jupyter: a mechanism shows itself as the browser app (:mod:`planardyn.app`:
drag, edit, simulate) above a summary table, a result as the app with its run loaded (when it
knows its model) above its summary; :func:`app_view` shows either where a cell ends.

The app's engine (about 1.35 MB, gzipped) is embedded once per notebook session: the first app
shown defines it in the notebook's page (``window.planardynApp``, a promise of the app's page),
and every app, that one included, is an iframe whose page is written from it with its own
model and run (a few kB to a few hundred kB). Where scripts do not run (a notebook rendered on
a web site, an untrusted notebook), the summary's SVG drawing stays in the app's place.

Everything here returns HTML strings; nothing needs IPython. :func:`register_display` hands
:func:`mechanism_html`, :func:`result_html` and :func:`point_motion_html` to IPython's HTML
formatter (``import planardyn`` does it inside IPython), so the model classes need not know
about notebooks. The result classes of the layers above (planned motions, sizing reports,
identifications...) show themselves: their ``_repr_html_`` is :class:`Summarized`'s, a table
of the rows they give, and their ``__repr__`` one line, never an array's contents.
"""

from __future__ import annotations

import base64
import gzip
import html
import json
import math
import sys
import uuid
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .app import DATA_ELEMENT, AppNotBuiltError, app_html, app_template, page_data, payloads
from .mechanism import Mechanism, from_result
from .plot import default_trace_points, pivot_points
from .result import PointMotion, SimulationResult

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


def mechanism_summary(mech: Mechanism) -> str:
    """The mechanism's summary: the drawing (SVG) beside a table of its bodies, pairs, mobility,
    coordinates, mass and gravity."""
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


def result_summary(result: SimulationResult) -> str:
    """The result's summary: status, span, counters and the range of every coordinate and
    drive effort; with the drawing of the last configuration and the point paths when the
    result knows its model (``result.metadata['model']``)."""
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


#: The app's height in a notebook (px): the drawing, its sliders and the charts in one view,
#: with no inner scroll: the header (43 px), two charts whole (342 px: web/src/charts.js's
#: --charts-min; at 640 px the second chart scrolled), the sliders and run or play controls
#: (85 to 100 px for two coordinates) and a drawing of at least 300 px (tests/test_app_browser.py's
#: notebook test).
APP_HEIGHT = 800
#: Whether this session's notebook page holds the engine (the first app shown defines it).
_engine_shown = False
#: Defines ``window.planardynApp`` in the notebook's page: a promise of the app's page, which
#: ships gzipped and base64-encoded (2.8 MB -> about 1.35 MB; the browser's DecompressionStream
#: inflates it), and tells the apps waiting for it.
ENGINE_SCRIPT = (
    '<script>window.planardynApp=(async()=>{{const b=atob("{b64}"),u=new Uint8Array(b.length);'
    "for(let i=0;i<b.length;i++)u[i]=b.charCodeAt(i);"
    'return await new Response(new Blob([u]).stream().pipeThrough(new DecompressionStream("gzip"))).text()}})();'
    'window.dispatchEvent(new Event("planardyn-app"));</script>'
)
#: Mounts one app: an iframe (scripts and downloads allowed, nothing else of the notebook's
#: page reachable) whose page is the engine's with this display's data; the summary's drawing
#: goes, its table stays. Without the engine after 10 s, a note says how to get it.
MOUNT_SCRIPT = (
    '<script>(()=>{{const id="{id}",root=document.getElementById(id),data=document.getElementById(id+"-data").textContent;'
    "const mount=(page)=>{{const f=document.createElement(\"iframe\");"
    'f.setAttribute("sandbox","allow-scripts allow-downloads");f.title="planardyn app";'
    'f.style.cssText="width:100%;height:{height}px;border:1px solid #dde";'
    "f.srcdoc=page.replace({empty},()=>{empty}.replace(\"{{}}\",data));root.prepend(f);"
    'const s=root.querySelector(".planardyn-summary svg");if(s)s.remove()}};'
    "const go=()=>window.planardynApp.then(mount);"
    'if(window.planardynApp)go();else{{window.addEventListener("planardyn-app",go,{{once:true}});'
    'setTimeout(()=>{{if(!window.planardynApp)root.querySelector(".planardyn-note").hidden=false}},10000)}}}})();</script>'
)
NO_ENGINE = (
    '<p class="planardyn-note" hidden>The app\'s engine is not in this page: the first planardyn app of '
    "the session holds it. Show <code>planardyn.notebook.engine()</code> in a cell, then run this one again.</p>"
)


class Html:
    """HTML for a notebook cell: shown by Jupyter (``_repr_html_``)."""

    def __init__(self, text: str) -> None:
        self.text = text

    def _repr_html_(self) -> str:
        return self.text


def engine() -> Html:
    """The app's engine for the notebook's page, as a cell's output: every app shown after it
    in this session uses it (needed only when the output that held it was cleared)."""
    global _engine_shown
    _engine_shown = True
    page = gzip.compress(app_template().encode("utf-8"), mtime=0)
    return Html(ENGINE_SCRIPT.format(b64=base64.b64encode(page).decode("ascii")))


def _app(summary: str, model: dict[str, str], run: dict[str, Any] | None, height: int) -> str:
    """An app above ``summary``, with the engine before it if the page has none yet; the
    summary alone when this installation has no built app."""
    try:
        first = "" if _engine_shown else engine().text
    except AppNotBuiltError:
        return summary
    id_ = f"planardyn-{uuid.uuid4().hex[:12]}"
    return (
        f'<div id="{id_}"><div class="planardyn-summary">{summary}</div>{NO_ENGINE}</div>{first}'
        f'<script type="application/json" id="{id_}-data">{page_data(model, run)}</script>'
        + MOUNT_SCRIPT.format(id=id_, height=height, empty=_js_string(DATA_ELEMENT))
    )


class AppView:
    """The app with a model (and a run) in a notebook cell, made when shown (the first shown
    carries the engine); :meth:`save` writes it as one offline page (as ``planardyn app`` does)."""

    def __init__(self, summary: str, model: dict[str, str], run: dict[str, Any] | None, height: int) -> None:
        self.model, self.run, self.height, self.summary = model, run, height, summary

    def _repr_html_(self) -> str:
        return _app(self.summary, self.model, self.run, self.height)

    def save(self, path: Any) -> None:
        """Write the app as one HTML file."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(app_html(self.model, self.run))


def app_view(model: Mechanism | SimulationResult, result: SimulationResult | None = None, *,
             height: int = APP_HEIGHT, **run_kw: Any) -> AppView:
    """The app in a notebook cell (its last line): ``app_view(mech)``, ``app_view(mech, res)``,
    or ``app_view(res)`` for a result that carries its model. ``run_kw`` go to
    :func:`planardyn.replay.run_data` (``channels``, ``traces``, ``max_frames``, ``title``)."""
    mech, run = (from_result(model), model) if isinstance(model, SimulationResult) else (model, result)
    summary = mechanism_summary(mech) if run is None else result_summary(run)
    return AppView(summary, *payloads(mech, run, **run_kw), height)


def mechanism_html(mech: Mechanism) -> str:
    """The mechanism's notebook view: the app above its summary (:func:`mechanism_summary`)."""
    return app_view(mech)._repr_html_()


def result_html(result: SimulationResult) -> str:
    """The result's notebook view: the app with the run above its summary when the result
    carries its model (:func:`result_summary`), else the summary."""
    if not (len(result.t) and result.metadata.get("model")):
        return result_summary(result)
    return app_view(result)._repr_html_()


def _js_string(text: str) -> str:
    """``text`` as a JavaScript string literal safe inside a script element."""
    return json.dumps(text).replace("<", "\\u003c")


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
