// The engine warmed in idle time. V8 runs a WebAssembly module's functions first from its
// baseline compiler (Liftoff) and recompiles the hot ones with its optimising one (TurboFan)
// only once they have run for a while, so in a fresh page the first simulation ran 10-30x
// slower than later ones (the 10 s four-bar: 30-94 ms, 3.2 ms warm; 8 ms after this warm-up;
// benchmarks/app_browser.py). Short runs of the model shown, made while the page is idle and
// within a budget, bring the integrator and the evaluation to full speed before a user's first
// run. The compiled code serves every model after, so this is done once a page. No result is kept.
import { app } from "./state.js";

/** Steps of one warm-up run: a bounded piece of work whatever the model, a few ms when cold. */
const WARM_STEPS = 40;
/** Wall time the warm-up may take in all (ms): past it, the rest tiers up in the user's runs. */
const WARM_BUDGET_MS = 300;
/** Idle time left below which no further run is started in this idle period (ms). */
const MIN_IDLE_MS = 4;

let started = false;

/** Warm the engine with the model shown, once a page; <body data-warm="1"> once done. */
export function warmEngine() {
  if (started || !app.mech) return;
  started = true;
  const t0 = performance.now();
  const over = () => performance.now() - t0 > WARM_BUDGET_MS;
  const step = (deadline) => {
    let failed = false;
    while (!failed && !over() && deadline.timeRemaining() > MIN_IDLE_MS) {
      try {
        app.mech.simulate({ maxSteps: WARM_STEPS }); // the model shown now: an edit may replace it
      } catch {
        failed = true; // a model that cannot run warms nothing
      }
    }
    if (failed || over()) {
      app.timings.warmMs = performance.now() - t0;
      document.body.dataset.warm = "1";
    } else requestIdleCallback(step);
  };
  requestIdleCallback(step);
}
