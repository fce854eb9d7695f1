// node tools/view/bundle.mjs [--check]
//
// Bundles the parts of three.js that `tcb view` pages use (three-entry.mjs)
// into one minified script that sets the global THREE, with three's MIT
// licence at its top, and writes crates/tcb-cli/src/view/three.min.js, which
// the `tcb` binary embeds (include_str!): building tcb, or a page, needs no
// node and no network. --check: exit 1 if the committed file differs from a
// fresh build (CI runs it after `npm ci --prefix tools/view`).
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";
import * as esbuild from "esbuild";

const here = path.dirname(fileURLToPath(import.meta.url));
const out = path.join(here, "../../crates/tcb-cli/src/view/three.min.js");
const three = JSON.parse(fs.readFileSync(path.join(here, "node_modules/three/package.json"), "utf8"));
const licence = fs.readFileSync(path.join(here, "node_modules/three/LICENSE"), "utf8").trim();
const banner =
  `/*! three.js r${three.version.split(".")[1]} (npm three@${three.version}): the parts that tcb view uses,\n` +
  ` * bundled by tools/view/bundle.mjs (esbuild ${esbuild.version}) from tools/view/three-entry.mjs.\n *\n` +
  licence.split("\n").map((l) => ` * ${l}`.trimEnd()).join("\n") +
  "\n */";
const result = await esbuild.build({
  entryPoints: [path.join(here, "three-entry.mjs")],
  bundle: true,
  format: "iife",
  globalName: "THREE",
  minify: true,
  legalComments: "none",
  target: "es2020",
  banner: { js: banner },
  write: false,
  logLevel: "warning",
});
const text = result.outputFiles[0].text;
// The page inlines the script: a "</script" inside it would end it early.
if (/<\/script/i.test(text)) {
  console.error("the bundle contains '</script', which would end the page's <script> early");
  process.exit(1);
}
if (process.argv.includes("--check")) {
  const committed = fs.existsSync(out) ? fs.readFileSync(out, "utf8") : "";
  if (committed !== text) {
    console.error(`${path.relative(process.cwd(), out)} differs from a fresh build; run: node tools/view/bundle.mjs`);
    process.exit(1);
  }
  console.log(`${path.relative(process.cwd(), out)}: as built from three@${three.version} (${text.length} bytes)`);
} else {
  fs.writeFileSync(out, text);
  console.log(`wrote ${path.relative(process.cwd(), out)} (${text.length} bytes, three@${three.version})`);
}
