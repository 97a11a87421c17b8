// Bundles the browser app into ONE offline HTML file: the engine (WebAssembly, inlined as
// base64 by esbuild's binary loader), its wasm-bindgen glue, uPlot and the app's own modules
// and styles. Run by `./dev app`:
//
//   node web/build.mjs PKG_DIR OUT_HTML
//
// PKG_DIR holds wasm-bindgen's `--target web` output (planardyn_wasm.js and the wasm-opt'ed
// planardyn_wasm_bg.wasm). The page keeps a placeholder script element that `planardyn app`
// fills with the model (and a run) as JSON.
import * as esbuild from "esbuild";
import { readFileSync, writeFileSync, mkdirSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));
const [pkg, out] = process.argv.slice(2).map((p) => resolve(p));
if (!pkg || !out) {
  console.error("usage: node web/build.mjs PKG_DIR OUT_HTML");
  process.exit(2);
}

// `import ... from "planardyn-engine"` resolves to the glue wasm-bindgen wrote.
const engine = {
  name: "planardyn-engine",
  setup(build) {
    build.onResolve({ filter: /^planardyn-engine(\/wasm)?$/ }, (args) => ({
      path: args.path.endsWith("/wasm") ? join(pkg, "planardyn_wasm_bg.wasm") : join(pkg, "planardyn_wasm.js"),
    }));
  },
};

const js = await esbuild.build({
  entryPoints: [join(here, "src", "main.js")],
  bundle: true,
  format: "iife",
  target: "es2020",
  minify: true,
  legalComments: "none",
  loader: { ".wasm": "binary" },
  // wasm-bindgen's async init reads import.meta.url; the page uses initSync with the inlined bytes.
  logOverride: { "empty-import-meta": "silent" },
  plugins: [engine],
  write: false,
});
const css = await esbuild.build({
  entryPoints: [join(here, "src", "app.css")],
  bundle: true,
  minify: true,
  write: false,
});

// Inside an inline script, "</script" would end it: escape the slash (same string in JS).
const inline = (text) => text.replace(/<\/(script|style)/gi, "<\\/$1");
const template = readFileSync(join(here, "app.html"), "utf8");
const page = template
  .replace("/*APP_CSS*/", () => inline(css.outputFiles[0].text))
  .replace("/*APP_JS*/", () => inline(js.outputFiles[0].text));
mkdirSync(dirname(out), { recursive: true });
writeFileSync(out, page);
console.log(`${out}: ${(page.length / 1024).toFixed(0)} KiB`);
