// The drawing of a mechanism at one state, through a "pen" with two back ends: the page's
// canvas and an SVG document (the export). A scene is what one frame shows, in world
// coordinates (m): every carried point's position, the bodies as polygons of their points,
// the ground's points, each pair's geometry from the engine, reaction arrows and point paths.

const COLORS = ["#1f6fb2", "#d9730d", "#2e8540", "#8e44ad", "#b3261e", "#0f7c80", "#7a5c00", "#c2185b"];
/** Longest reaction arrow, as a fraction of the mechanism's size L. */
const ARROW_FRACTION = 0.3;
/** Margin around the fitted view, as a fraction of L. */
const PAD_FRACTION = 0.12;

/** The nice number (1, 2 or 5 times a power of ten) nearest below v. */
export function niceBelow(v) {
  const p = 10 ** Math.floor(Math.log10(v));
  const m = v / p;
  return (m >= 5 ? 5 : m >= 2 ? 2 : 1) * p;
}

/** A length in m with a unit that keeps it short (mm under 0.1 m). */
export function formatLength(v) {
  return v < 0.1 ? `${+(v * 1000).toPrecision(3)} mm` : `${+v.toPrecision(3)} m`;
}

/** World bounds [xmin, xmax, ymin, ymax] of the finite points in `arrays` (each x, y, x, y...)
 * with a margin of PAD_FRACTION * scale. */
export function fitBounds(arrays, scale) {
  let [x0, x1, y0, y1] = [Infinity, -Infinity, Infinity, -Infinity];
  for (const a of arrays) {
    for (let i = 0; i + 1 < a.length; i += 2) {
      if (!Number.isFinite(a[i]) || !Number.isFinite(a[i + 1])) continue;
      x0 = Math.min(x0, a[i]); x1 = Math.max(x1, a[i]);
      y0 = Math.min(y0, a[i + 1]); y1 = Math.max(y1, a[i + 1]);
    }
  }
  const pad = PAD_FRACTION * scale;
  return [x0 - pad, x1 + pad, y0 - pad, y1 + pad];
}

/** Whether `bounds` [xmin, xmax, ymin, ymax] hold every finite point of `arrays` (x, y, ...). */
export function holds(bounds, arrays) {
  const [x0, x1, y0, y1] = bounds;
  return arrays.every((a) => {
    for (let i = 0; i + 1 < a.length; i += 2) {
      if (Number.isFinite(a[i]) && Number.isFinite(a[i + 1]) && (a[i] < x0 || a[i] > x1 || a[i + 1] < y0 || a[i + 1] > y1)) return false;
    }
    return true;
  });
}

/** The map from world (m, y up) to pixels (y down) showing `bounds` whole, centred. */
export function transform(bounds, width, height) {
  const [x0, x1, y0, y1] = bounds;
  const k = Math.min(width / (x1 - x0), height / (y1 - y0));
  const cx = (width - k * (x1 - x0)) / 2 - k * x0;
  const cy = (height + k * (y1 - y0)) / 2 + k * y0;
  return { k, px: (x) => cx + k * x, py: (y) => cy - k * y, wx: (px) => (px - cx) / k, wy: (py) => (cy - py) / k };
}

/** A pen drawing on a 2-D canvas context. */
export function canvasPen(ctx) {
  const stroke = (s) => { ctx.strokeStyle = s.stroke || "#000"; ctx.lineWidth = s.width || 1; ctx.setLineDash(s.dash || []); ctx.stroke(); };
  return {
    clear(w, h) { ctx.clearRect(0, 0, w, h); },
    path(pts, s) {
      if (pts.length < 4) return;
      ctx.beginPath();
      ctx.moveTo(pts[0], pts[1]);
      for (let i = 2; i < pts.length; i += 2) ctx.lineTo(pts[i], pts[i + 1]);
      if (s.close) ctx.closePath();
      if (s.fill) { ctx.fillStyle = s.fill; ctx.fill(); }
      if (s.stroke) stroke(s);
    },
    circle(x, y, r, s) {
      ctx.beginPath();
      ctx.arc(x, y, r, 0, 2 * Math.PI);
      if (s.fill) { ctx.fillStyle = s.fill; ctx.fill(); }
      if (s.stroke) stroke(s);
    },
    text(x, y, str, s) {
      ctx.fillStyle = s.fill || "#000";
      ctx.font = s.font || "12px system-ui, sans-serif";
      ctx.textAlign = s.align || "left";
      ctx.fillText(str, x, y);
    },
  };
}

/** A pen writing SVG elements; `svg(w, h)` gives the document. */
export function svgPen() {
  const out = [];
  const attrs = (s) =>
    `fill="${s.fill || "none"}" stroke="${s.stroke || "none"}" stroke-width="${s.width || 1}"` +
    (s.dash ? ` stroke-dasharray="${s.dash.join(" ")}"` : "");
  const esc = (t) => t.replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]);
  const f = (v) => +v.toFixed(2);
  return {
    clear() { out.length = 0; },
    path(pts, s) {
      if (pts.length < 4) return;
      const d = [];
      for (let i = 0; i < pts.length; i += 2) d.push(`${i ? "L" : "M"}${f(pts[i])} ${f(pts[i + 1])}`);
      out.push(`<path d="${d.join("")}${s.close ? "Z" : ""}" ${attrs(s)}/>`);
    },
    circle(x, y, r, s) { out.push(`<circle cx="${f(x)}" cy="${f(y)}" r="${f(r)}" ${attrs(s)}/>`); },
    text(x, y, str, s) {
      const anchor = { left: "start", center: "middle", right: "end" }[s.align || "left"];
      out.push(`<text x="${f(x)}" y="${f(y)}" text-anchor="${anchor}" font-family="sans-serif" font-size="12" fill="${s.fill || "#000"}">${esc(str)}</text>`);
    },
    svg(w, h) {
      return `<svg xmlns="http://www.w3.org/2000/svg" width="${w}" height="${h}" viewBox="0 0 ${w} ${h}">` +
        `<rect width="${w}" height="${h}" fill="#fff"/>${out.join("")}</svg>`;
    },
  };
}

/** Draw `scene` with `pen` in a w x h area through the transform `tr`. */
export function drawScene(pen, scene, tr, w, h) {
  const { points, bodies, ground, geometry, arrows, paths, scale } = scene;
  const P = (i) => [tr.px(points[2 * i]), tr.py(points[2 * i + 1])];
  pen.clear(w, h);
  for (const path of paths) {
    const px = [];
    for (let i = 0; i + 1 < path.length; i += 2) px.push(tr.px(path[i]), tr.py(path[i + 1]));
    pen.path(px, { stroke: "#9aa8b6", width: 1, dash: [4, 3] });
  }
  for (const g of ground) {
    const [x, y] = P(g);
    const a = 9;
    pen.path([x, y, x - a, y + 1.6 * a, x + a, y + 1.6 * a], { close: true, fill: "#e3e7eb", stroke: "#5d6b7a" });
  }
  bodies.forEach((body, b) => {
    const pts = body.flatMap((i) => P(i)).filter(Number.isFinite);
    const color = COLORS[b % COLORS.length];
    if (pts.length >= 6) pen.path(pts, { close: true, fill: color + "22", stroke: color, width: 3 });
    else pen.path(pts, { stroke: color, width: 5 });
  });
  for (const g of geometry) {
    for (let i = 0; i + 3 < g.lines.length; i += 4) {
      pen.path([tr.px(g.lines[i]), tr.py(g.lines[i + 1]), tr.px(g.lines[i + 2]), tr.py(g.lines[i + 3])],
        { stroke: "#5d6b7a", width: 1.5 });
    }
    for (let i = 0; i + 2 < g.circles.length; i += 3) {
      pen.circle(tr.px(g.circles[i]), tr.py(g.circles[i + 1]), tr.k * g.circles[i + 2], { stroke: "#5d6b7a", dash: [5, 3] });
    }
    for (let i = 0; i + 1 < g.blocks.length; i += 2) {
      const [x, y] = [tr.px(g.blocks[i]), tr.py(g.blocks[i + 1])];
      pen.path([x - 8, y - 6, x + 8, y - 6, x + 8, y + 6, x - 8, y + 6], { close: true, fill: "#fff", stroke: "#1d2733", width: 1.5 });
    }
    for (let i = 0; i + 1 < g.pins.length; i += 2) {
      pen.circle(tr.px(g.pins[i]), tr.py(g.pins[i + 1]), 4.5, { fill: "#fff", stroke: "#1d2733", width: 1.5 });
    }
  }
  drawArrows(pen, arrows, tr, scale);
  scaleBar(pen, tr, w, h);
}

/** The tip (m) of the reaction arrow of `item` {x, y, fx, fy}: the force `ref` (N) is drawn
 * ARROW_FRACTION of L long, a force beyond twice the reference (near a singularity) at twice
 * that length. The view holds every tip (view.js). */
export function arrowTip({ x, y, fx, fy }, ref, scale) {
  const len = (ARROW_FRACTION * scale * Math.min(Math.hypot(fx, fy) / ref, 2)) / (Math.hypot(fx, fy) || 1);
  return [x + fx * len, y + fy * len];
}

/** Reaction arrows: `arrows.items` [{x, y, fx, fy}] to their tips (arrowTip with `arrows.ref`). */
function drawArrows(pen, arrows, tr, scale) {
  if (!arrows || !(arrows.ref > 0)) return;
  for (const item of arrows.items) {
    const [tx, ty] = arrowTip(item, arrows.ref, scale);
    const [x0, y0, x1, y1] = [tr.px(item.x), tr.py(item.y), tr.px(tx), tr.py(ty)];
    const n = Math.hypot(x1 - x0, y1 - y0);
    if (!(n > 2)) continue;
    const [ux, uy] = [(x1 - x0) / n, (y1 - y0) / n];
    const style = { stroke: "#b3261e", width: 2 };
    pen.path([x0, y0, x1, y1], style);
    pen.path([x1 - 8 * ux + 4 * uy, y1 - 8 * uy - 4 * ux, x1, y1, x1 - 8 * ux - 4 * uy, y1 - 8 * uy + 4 * ux], style);
  }
}

/** A scale bar of a nice length (about a fifth of the width) in the lower left corner. */
function scaleBar(pen, tr, w, h) {
  const length = niceBelow(w / 5 / tr.k);
  const [x, y, px] = [14, h - 14, length * tr.k];
  pen.path([x, y - 5, x, y, x + px, y, x + px, y - 5], { stroke: "#1d2733", width: 1.5 });
  pen.text(x + px / 2, y - 8, formatLength(length), { align: "center", fill: "#1d2733" });
}
