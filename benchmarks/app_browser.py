"""The browser app's engine (planardyn as WebAssembly, in headless chromium) against the native
extension (the same Rust through the Python API), measured in one run on this machine:

- a 10 s passive four-bar run (four-bar-gravity, the model's settings: DOP853, rtol 1e-9);
- a 3-RRR's drive efforts and pair reactions for one frame (planardyn::dynamics::evaluate in
  the page; native: inverse_dynamics then reactions through the Python API, so the native
  figure includes two Python calls);
- a 5R's 100 x 100 singularity map over its two coordinates (the page's map, web/src/map.js
  over planardyn::dynamics::sigma_rows: each cell placed by the closed forms on the current
  state's branch; native: a continuation loop in Python over Mechanism.kinematics, which also
  computes the analogues u and w: the Python API has no call for the map, so the native
  figure is the Python user's);
- the 3-RRR's 100 x 100 singularity map over its first two inputs, the third held (the same
  page map: each cell placed on the current state's branch along its path from it,
  planardyn::kinematics::BranchPath, the triad's Newton a step; native: the same Python loop);
- the compliant 5R's (the shipped five-bar-compliant: elastic motors and end-effector pin) 100 x 100
  map of its first natural frequency (web/src/map.js over planardyn::elastic::map_rows; the
  page's only: the Python API has no call for it);
- the engine's size (wasm, the page, gzipped) and the page's load time to its first drawing.

The four-bar run and the 3-RRR frame are timed as a user meets them: the FIRST call in a fresh
page once the page has warmed its engine in idle time (web/src/warm.js: V8 runs a module's
functions first from its baseline compiler, Liftoff, and recompiles the hot ones with TurboFan
once they have run for a while; the warm-up's own time is printed too) and the steady
state, the median of REPEAT calls after WARM warm-up calls (native: the same median), with their
least beside it (on a machine shared with other work the median takes the other processes' turns
too; the least is the code's own speed). The maps are timed once, the load as the best of LOADS fresh pages.

    .venv/bin/python benchmarks/app_browser.py            # needs ./dev setup (builds the app) and chromium
"""

from __future__ import annotations

import gzip
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import planardyn as pdy
from planardyn.app import app_html, app_template, model_payload
from playwright.sync_api import sync_playwright

ROOT = Path(__file__).resolve().parents[1]
WASM = ROOT / "target" / "app" / "pkg" / "planardyn_wasm_bg.wasm"
REPEAT = 31
#: Calls before the steady state is timed: enough for V8 to have tiered the hot functions up
#: (the four-bar's run settles after 2-10 calls in headless chromium 156).
WARM = 20
LOADS = 15
FRAMES = 200
MAP_N = 100


def steady(f, repeat: int = REPEAT) -> tuple[float, float]:
    """Median and least wall time (s) of `repeat` calls of f after WARM calls."""
    times = []
    for _ in range(WARM + repeat):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return float(np.median(times[WARM:])), min(times[WARM:])


def once(f) -> float:
    """Wall time (s) of one call of f."""
    t0 = time.perf_counter()
    f()
    return time.perf_counter() - t0


def native() -> dict[str, float]:
    four = pdy.load(pdy.models.path("four-bar-gravity"))
    out = dict(zip(("sim", "simBest"), steady(lambda: four.simulate(t_end=10.0))))
    rrr = pdy.load(pdy.models.path("3-rrr"))
    q0 = rrr.q0
    qs = [q0 + 0.05 * np.sin(0.1 * k) for k in range(FRAMES)]
    qd, qdd = np.full(rrr.dof, 0.2), np.full(rrr.dof, 0.5)

    def frames() -> None:
        for q in qs:
            tau = rrr.inverse_dynamics(q, qd, qdd)
            rrr.reactions(q, qd, tau=tau)

    out["frame"], out["frameBest"] = (t / FRAMES for t in steady(frames))
    five = pdy.load(pdy.models.path("five-bar"))
    out["map"] = once(lambda: python_map(five))
    out["rrrMap"] = once(lambda: python_map(rrr))
    return out


def python_map(mech: pdy.Mechanism) -> np.ndarray:
    """The page's map (web/src/map.js) through the Python API: over the first two coordinates
    (the others held), a serpentine over the grid, each cell continued from the last."""
    q0 = mech.q0
    lo, hi = q0 - np.pi, q0 + np.pi
    axis = [lo[k] + (hi[k] - lo[k]) * (np.arange(MAP_N) + 0.5) / MAP_N for k in range(2)]
    sigma = np.full((MAP_N, MAP_N), np.nan)
    x = row_start = mech.assemble(q0)
    q = np.array(q0, dtype=float)
    for j in range(MAP_N):
        for i in range(MAP_N):
            ii = MAP_N - 1 - i if j % 2 else i
            q[0], q[1] = axis[0][ii], axis[1][j]
            try:
                k = mech.kinematics(q, x_start=x)
                x, sigma[j, ii] = k["x"], k["sigma_min"]
                if i == 0:
                    row_start = x
            except pdy.PlanardynError:
                x = row_start
    return sigma


PAGE_BENCH = """async ([four, rrr, compliant, frames, mapN, repeat, warm]) => {
  const a = window.planardyn, pd = a.pd;
  const once = (f) => { const t = performance.now(); f(); return (performance.now() - t) / 1000; };
  // [the first call, the median and the least of `repeat` calls after `warm` more] (s)
  const firstAndSteady = (f) => {
    const t = [...Array(1 + warm + repeat)].map(() => once(f));
    const rest = t.slice(1 + warm).sort((x, y) => x - y);
    return [t[0], rest[rest.length >> 1], rest[0]];
  };
  const fm = pd.load(four, "yaml", "four-bar-gravity.yaml");
  const [simFirst, sim, simBest] = firstAndSteady(() => fm.simulate({t_end: 10}));
  const m = pd.load(rrr, "yaml", "3-rrr.yaml"), info = m.info(), q0 = info.q0, n = info.dof;
  const qs = [...Array(frames).keys()].map((k) => q0.map((v) => v + 0.05 * Math.sin(0.1 * k)));
  const qd = new Float64Array(n).fill(0.2), qdd = new Float64Array(n).fill(0.5);
  const [frameFirst, frame, frameBest] = firstAndSteady(() => { let x; for (const q of qs) x = m.evaluate(q, qd, qdd, x).x; }).map((t) => t / frames);
  const five = a.mech;
  const { mapRanges, mapper, sigmaRows } = a.mapTools;
  const { frequencyRows } = a.mapTools;
  const mapOf = (mech, rows) => {
    const info = mech.info();
    return once(() => mapper(rows(mech), mapRanges(info, info.q0), mapN, mech.assemble(info.q0), info.q0).step(Infinity));
  };
  const map = mapOf(five, sigmaRows);
  const rrrMap = mapOf(m, sigmaRows);
  const frequencyMap = mapOf(pd.load(compliant, "yaml", "compliant.yaml"), frequencyRows);
  return { simFirst, sim, simBest, frameFirst, frame, frameBest, map, rrrMap, frequencyMap, load: a.timings.readyMs / 1000, engine: a.timings.engineMs / 1000, warm: a.timings.warmMs / 1000 };
}"""


def browser() -> dict[str, float]:
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        sys.exit("chromium is needed (./dev installs Debian's as root)")
    with tempfile.TemporaryDirectory() as tmp, sync_playwright() as p:
        page_file = Path(tmp) / "app.html"
        page_file.write_text(app_html(model_payload(pdy.models.path("five-bar"))), encoding="utf-8")
        b = p.chromium.launch(executable_path=chromium, args=["--no-sandbox"])
        loads = []
        for _ in range(LOADS):
            page = b.new_page()
            page.goto(page_file.as_uri())
            page.wait_for_selector("body[data-ready='1']", timeout=30_000)
            loads.append(page.evaluate("window.planardyn.timings"))
            page.close()
        page = b.new_page()
        page.goto(page_file.as_uri())
        page.wait_for_selector("body[data-warm='1']", timeout=30_000)
        texts = [pdy.models.path(n).read_text() for n in ("four-bar-gravity", "3-rrr", "five-bar-compliant")]
        out = page.evaluate(PAGE_BENCH, [*texts, FRAMES, MAP_N, REPEAT, WARM])
        b.close()
    out["load"] = min(t["readyMs"] for t in loads) / 1000
    out["engine"] = min(t["engineMs"] for t in loads) / 1000
    return out


def main() -> None:
    page = app_template().encode()
    wasm = WASM.read_bytes() if WASM.exists() else b""
    nat, web = native(), browser()
    print(f"engine: {len(wasm) / 1e6:.2f} MB wasm ({len(gzip.compress(wasm)) / 1e6:.2f} MB gzipped); "
          f"the app page {len(page) / 1e6:.2f} MB ({len(gzip.compress(page)) / 1e6:.2f} MB gzipped)")
    print(f"page load to the first drawing: {web['load'] * 1e3:.0f} ms (the engine's instantiation {web['engine'] * 1e3:.0f} ms)")
    print(f"browser, native: the median of {REPEAT} calls after {WARM} (best: their least); "
          f"first: the first call in a fresh page after its idle warm-up ({web['warm'] * 1e3:.0f} ms); load average {os.getloadavg()[0]:.1f}")
    print(f"{'':44s} {'browser':>10s} {'native':>10s} {'ratio':>7s} {'best':>15s} {'first':>10s}")
    rows = [("10 s passive four-bar run", "sim", 1e3, "ms"),
            ("3-RRR efforts + reactions, one frame", "frame", 1e6, "us"),
            (f"5R singularity map {MAP_N} x {MAP_N}", "map", 1e3, "ms"),
            (f"3-RRR singularity map {MAP_N} x {MAP_N}", "rrrMap", 1e3, "ms")]
    for label, key, scale, unit in rows:
        timed = key + "First" in web
        first = f"{web[key + 'First'] * scale:10.3g}" if timed else f"{'-':>10s}"
        best_ = f"{web[key + 'Best'] * scale:7.3g} {nat[key + 'Best'] * scale:7.3g}" if timed else f"{'-':>15s}"
        print(f"{label + f' ({unit})':44s} {web[key] * scale:10.3g} {nat[key] * scale:10.3g} "
              f"{web[key] / nat[key]:7.2f} {best_} {first}")
    label = f"compliant 5R first-frequency map {MAP_N} x {MAP_N} (ms)"
    print(f"{label:44s} {web['frequencyMap'] * 1e3:10.3g} {'-':>10s} {'-':>7s}")


if __name__ == "__main__":
    main()
