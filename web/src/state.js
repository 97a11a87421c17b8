// The app's state, one object (`window.planardyn`, for scripts and tests), and the helpers
// every part of the page uses: an element by id, the status line, number formatting.

export const $ = (id) => document.getElementById(id);

export const app = {
  pd: null, mech: null, info: null, text: "", format: "yaml", source: "",
  q: null, x: null, ev: null, bounds: null, viewContent: [], sweepStates: [], paths: [], arrowRef: 0,
  mode: "design", active: 0, run: null, frame: 0, playing: false, replay: null,
  charts: null, map: null, errors: [],
};

export function status(text, bad = false) {
  $("status").textContent = text;
  $("status").classList.toggle("bad", bad);
}

export const zeros = () => new Float64Array(app.info.dof);
export const fmt = (v) => (Number.isFinite(v) ? (Math.abs(v) >= 1e4 || (Math.abs(v) < 1e-3 && v !== 0) ? v.toExponential(3) : v.toPrecision(4)) : "–");
