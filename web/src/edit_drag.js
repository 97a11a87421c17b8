// Editing the model's drawing on the page: Shift + drag a point (a ground point too) moves
// where the model file draws it (its line under `points:` in YAML text, its entry of the
// top-level "points" object in JSON text), and the model is
// rebuilt as it moves (bodies' lengths, masses and inertias follow their points), shown as
// drawn; an edit that breaks it shows the loader's error in place, the last good model kept.
import { $, app, status } from "./state.js";
import { nearestPoint, pointerWorld } from "./design.js";
import { setModel } from "./model.js";

/** A dragged point is written to this fraction of the mechanism's size L (rounded to a
 * decimal place): 0.1 mm on a 1 m linkage, no long tails of digits in the file. */
const SNAP_FRACTION = 1e-4;

/** The model text with point `name` drawn at [x, y] (m; `decimals` places): its line
 * `name: [x, y]` under the top-level `points:` rewritten (a comment on it goes: it described
 * the old place). Null where the point is not written so. */
export function movePoint(text, name, [x, y], decimals) {
  const lines = text.split("\n");
  const start = lines.findIndex((l) => /^points:\s*(#.*)?$/.test(l));
  if (start < 0) return null;
  const key = new RegExp(`^(\\s+"?${name.replace(/[^\w]/g, "\\$&")}"?\\s*:\\s*)\\[[^\\]]*\\]`);
  for (let i = start + 1; i < lines.length && (/^\s/.test(lines[i]) || lines[i].trim() === ""); i++) {
    const m = lines[i].match(key);
    if (m) {
      lines[i] = `${m[1]}[${x.toFixed(decimals)}, ${y.toFixed(decimals)}]`;
      return lines.join("\n");
    }
  }
  return null;
}

/** Index just past the JSON string that opens at `i` (a quote). */
function stringEnd(text, i) {
  for (let k = i + 1; k < text.length; k++) {
    if (text[k] === "\\") k++;
    else if (text[k] === '"') return k + 1;
  }
  return text.length;
}

/** Where the value of the member at `path` (keys from the top-level object) begins in JSON
 * text, or -1: a scan that tracks the keys of the enclosing objects (an array's items have
 * none). */
function memberStart(text, path) {
  const stack = [], keys = [];
  for (let i = 0; i < text.length;) {
    const c = text[i];
    if (c === '"') {
      const end = stringEnd(text, i);
      let k = end;
      while (/\s/.test(text[k] || "")) k++;
      const d = stack.length - 1;
      if (text[k] !== ":" || stack[d] !== "{") { i = end; continue; }
      const key = JSON.parse(text.slice(i, end));
      const here = [...keys.slice(0, d), key];
      for (i = k + 1; /\s/.test(text[i] || "");) i++;
      if (here.length === path.length && here.every((s, j) => s === path[j])) return i;
      keys[d] = key;
      continue;
    }
    if (c === "{" || c === "[") { stack.push(c); keys[stack.length - 1] = c === "[" ? null : undefined; }
    else if (c === "}" || c === "]") stack.pop();
    i++;
  }
  return -1;
}

/** As `movePoint` for JSON text: the top-level "points" object's `name: [x, y]` rewritten in
 * place (the rest of the text as written). Null where the point is not written so. */
export function movePointJson(text, name, [x, y], decimals) {
  let model;
  try { model = JSON.parse(text); } catch { return null; }
  const p = model && model.points && model.points[name];
  if (!Array.isArray(p) || p.length !== 2 || !p.every((v) => typeof v === "number")) return null;
  const start = memberStart(text, ["points", name]);
  if (start < 0 || text[start] !== "[") return null;
  const end = text.indexOf("]", start) + 1;
  return `${text.slice(0, start)}[${x.toFixed(decimals)}, ${y.toFixed(decimals)}]${text.slice(end)}`;
}

export function installEditDrag() {
  const c = $("drawing");
  let edit = null, pending = null;
  const apply = () => {
    const at = pending;
    pending = null;
    if (!edit || !at) return;
    const p = [edit.p0[0] + at[0] - edit.w0[0], edit.p0[1] + at[1] - edit.w0[1]];
    const decimals = Math.max(0, -Math.floor(Math.log10(SNAP_FRACTION * app.info.scale)));
    const json = app.format === "json";
    const text = (json ? movePointJson : movePoint)($("editor").value, edit.name, p, decimals);
    if (!text) {
      const where = json ? `"${edit.name}": [x, y] in the top-level "points" object` : `${edit.name}: [x, y] under points:`;
      status(`point ${edit.name} is not written as ${where} in the model text, so it cannot be dragged; edit it in the Model tab`, true);
      return;
    }
    setModel(text, app.format, app.source, { drawn: true });  // the view stays put while it holds the mechanism
    app.showState();
  };
  c.addEventListener("pointerdown", (e) => {
    if (!e.shiftKey || app.mode === "replay" || !app.mech) return;
    const i = nearestPoint(e, true);
    if (i === null) return;
    // Where the file draws the point: the carried point at the drawn body coordinates.
    const drawnAt = app.mech.points(app.info.x0);
    edit = { name: app.info.points[i], p0: [drawnAt[2 * i], drawnAt[2 * i + 1]], w0: pointerWorld(e) };
    c.setPointerCapture(e.pointerId);
    c.classList.add("dragging");
    document.body.dataset.editing = edit.name;
  });
  c.addEventListener("pointermove", (e) => {
    if (!edit) return;
    if (!pending) requestAnimationFrame(apply);
    pending = pointerWorld(e);
  });
  const release = () => {
    edit = null;
    c.classList.remove("dragging");
    delete document.body.dataset.editing;
  };
  c.addEventListener("pointerup", release);
  c.addEventListener("pointercancel", release);
}
