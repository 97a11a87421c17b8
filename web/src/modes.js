// The natural modes of a compliant model (one with a `compliance:` section) about the current
// pose, in the Modes tab: frequency and damping ratio of each (the engine's `modes`:
// planardyn::elastic::modes, the motors held); a mode clicked is animated on the drawing, the
// pose displaced along its shape at one cycle a second (its true period is far shorter), the
// largest point displacement MODE_FRACTION of the mechanism's size.
import { $, app, fmt } from "./state.js";
import { describe } from "./engine.js";
import { redraw, stopMode } from "./view.js";

/** Largest point displacement of a shown mode, as a fraction of L. */
const MODE_FRACTION = 0.08;
/** Seconds a shown mode's cycle takes. */
const CYCLE_S = 1;
/** Relative size of the displacement that measures a shape's point motion (linear there). */
const PROBE = 1e-6;

/** List the modes about the current state (only while the tab is open). */
export function listModes() {
  const note = $("modes-note"), table = $("modes");
  stopMode();
  app.modes = null;
  table.replaceChildren();
  if (!app.info || !$("tab-modes").classList.contains("on")) return;
  if (!app.info.compliant) {
    note.textContent = "Natural modes need the model's compliances: a compliance: section (drives, pairs or links; see the stiffness page of the docs).";
    return;
  }
  try {
    app.modes = app.mech.modes(app.q, false, app.x);
  } catch (err) {
    note.textContent = describe(err);
    return;
  }
  const { omega, dampingRatio } = app.modes;
  note.textContent = `${omega.length} modes about the current pose, the motors held; click one to see its shape (shown at one cycle a second).`;
  table.innerHTML = "<tr><th>mode</th><th>f (Hz)</th><th>ζ</th></tr>" + Array.from(omega, (w, k) =>
    `<tr data-mode="${k}"><td>${k + 1}</td><td class="num">${fmt(w / (2 * Math.PI))}</td><td class="num">${fmt(dampingRatio[k])}</td></tr>`).join("");
  table.querySelectorAll("tr[data-mode]").forEach((tr) => tr.addEventListener("click", () => showMode(+tr.dataset.mode)));
}

/** The shape of mode k (3n body displacements) scaled so that its largest point moves
 * MODE_FRACTION of L: the points' motion per unit of shape measured by a small displacement. */
export function modeShape(k) {
  const nx = app.info.x0.length;
  const shape = app.modes.shapes.subarray(k * nx, (k + 1) * nx);
  const x = app.x;
  const s = PROBE / Math.max(...shape.map(Math.abs));
  const moved = app.mech.points(x.map((v, i) => v + s * shape[i]));
  const rest = app.mech.points(x);
  let d = 0;
  for (let i = 0; i + 1 < rest.length; i += 2) d = Math.max(d, Math.hypot(moved[i] - rest[i], moved[i + 1] - rest[i + 1]) / s);
  const a = (MODE_FRACTION * app.info.scale) / d;
  return shape.map((v) => a * v);
}

/** Animate mode k on the drawing until the state changes. */
export function showMode(k) {
  const shape = modeShape(k);
  const x = app.x, token = {};
  app.modeAnim = token;
  document.body.dataset.modeShown = String(k + 1);
  const t0 = performance.now();
  const tick = (now) => {
    if (app.modeAnim !== token) return;
    const phase = Math.sin((2 * Math.PI * (now - t0)) / (1000 * CYCLE_S));
    app.modeX = x.map((v, i) => v + phase * shape[i]);
    redraw();
    requestAnimationFrame(tick);
  };
  requestAnimationFrame(tick);
}
