// Files: opening or dropping a model (.yaml, .json) or a Python run's data (.json), starting
// from a shipped model, and the exports (the model's text, the charts' CSV, the drawing as PNG
// or SVG).
import { $, app } from "./state.js";
import { toCsv } from "./channels.js";
import { isRun } from "./replay.js";
import { drawingSvg } from "./view.js";
import { setModel } from "./model.js";
import { showReplay } from "./run.js";

function openText(name, text) {
  if (/\.json$/i.test(name)) {
    let data = null;
    try { data = JSON.parse(text); } catch { /* not JSON: the loader says where */ }
    if (data && isRun(data)) return showReplay(data);
  }
  setModel(text, /\.json$/i.test(name) ? "json" : "yaml", name);
}

function download(name, blob) {
  const a = Object.assign(document.createElement("a"), { href: URL.createObjectURL(blob), download: name });
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}

export function installFiles() {
  $("open").addEventListener("change", async (e) => {
    const f = e.target.files[0];
    if (f) openText(f.name, await f.text());
  });
  window.addEventListener("dragover", (e) => { e.preventDefault(); $("drop-hint").hidden = false; });
  window.addEventListener("dragleave", () => { $("drop-hint").hidden = true; });
  window.addEventListener("drop", async (e) => {
    e.preventDefault();
    $("drop-hint").hidden = true;
    const f = e.dataTransfer.files[0];
    if (f) openText(f.name, await f.text());
  });
  const base = () => (app.info ? app.info.name.replace(/[^\w.-]+/g, "_") : "planardyn");
  $("export-model").onclick = () => download(`${base()}.${app.format === "json" ? "json" : "yaml"}`, new Blob([$("editor").value], { type: "text/plain" }));
  $("export-csv").onclick = () => {
    const { x, xLabel, chans } = app.charts;
    download(`${base()}.csv`, new Blob([toCsv(xLabel, x, chans)], { type: "text/csv" }));
  };
  $("export-png").onclick = () => $("drawing").toBlob((b) => download(`${base()}.png`, b));
  $("export-svg").onclick = () => download(`${base()}.svg`, new Blob([drawingSvg()], { type: "image/svg+xml" }));
}

/** The menu of the shipped models (`planardyn app` puts their text in the page): one chosen
 * is loaded as a file opened. */
export function installShipped(models) {
  const sel = $("shipped");
  for (const name of Object.keys(models)) sel.append(new Option(name, name));
  sel.hidden = false;
  sel.addEventListener("change", () => {
    if (sel.value) setModel(models[sel.value], "yaml", `${sel.value}.yaml`);
    sel.value = "";
  });
}
