// The engine: planardyn compiled to WebAssembly, its bytes inlined in the page (esbuild's
// binary loader), instantiated synchronously once.
import { initSync, load, lastPanic, version } from "planardyn-engine";
import wasmBytes from "planardyn-engine/wasm";

let ready = false;

/** The engine's functions, instantiated on first use. */
export function engine() {
  if (!ready) {
    initSync({ module: wasmBytes });
    ready = true;
  }
  return { load, version, lastPanic };
}

/** The message to show for an error thrown by the engine: a JS error of a planardyn class
 * (name, message and its fields), or an abort (a panic: a bug in planardyn) with its message. */
export function describe(err) {
  if (err instanceof WebAssembly.RuntimeError) {
    const panic = lastPanic();
    return `internal error in planardyn (a bug: please report it with the model): ${panic || err.message}`;
  }
  return err && err.message ? err.message : String(err);
}
