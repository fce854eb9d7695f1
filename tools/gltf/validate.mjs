// Validate glTF/GLB files with the Khronos glTF-Validator.
//   node tools/gltf/validate.mjs FILE...
// Prints each file's error, warning, info and hint counts and every error
// and warning message; exits 1 if any file has an error.
import fs from "node:fs";
import path from "node:path";
import validator from "gltf-validator";

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error("usage: node validate.mjs FILE.glb|FILE.gltf...");
  process.exit(2);
}
let failed = false;
for (const file of files) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        const at = path.resolve(path.dirname(file), decodeURIComponent(uri));
        fs.readFile(at, (err, data) => (err ? reject(err.toString()) : resolve(new Uint8Array(data))));
      }),
  });
  const i = report.issues;
  console.log(
    `${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints`
  );
  for (const m of i.messages) {
    if (m.severity <= (process.env.VERBOSE ? 3 : 1)) {
      const kind = ["error", "warning", "info", "hint"][m.severity];
      console.log(`  ${kind} ${m.code} at ${m.pointer ?? "-"}: ${m.message}`);
    }
  }
  if (i.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
