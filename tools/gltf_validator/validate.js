// Runs the Khronos glTF validator (npm gltf-validator, installed beside this
// file by `npm install --prefix tools/gltf_validator`) over each file named:
// one line a file with its error, warning, info and hint counts, then each
// error. Exit 0 when no file has an error, 1 when one has, 2 on a file it
// cannot read, 77 when the package is not installed.
"use strict";
const fs = require("fs");
const path = require("path");

let validator;
try {
  validator = require("gltf-validator");
} catch (e) {
  console.log("SKIP: gltf-validator is not installed (npm install --prefix tools/gltf_validator)");
  process.exit(77);
}

async function validate(file) {
  const bytes = fs.readFileSync(file);
  const report = await validator.validateBytes(new Uint8Array(bytes), {
    uri: path.basename(file),
    maxIssues: 0,
    externalResourceFunction: (uri) =>
      fs.promises.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))),
  });
  const i = report.issues;
  console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints`);
  for (const m of i.messages)
    if (m.severity === 0) console.log(`  error ${m.code} at ${m.pointer || "(file)"}: ${m.message}`);
  return i.numErrors;
}

(async () => {
  let errors = 0;
  for (const file of process.argv.slice(2)) {
    try {
      errors += await validate(file);
    } catch (e) {
      console.log(`${file}: cannot validate: ${e}`);
      process.exit(2);
    }
  }
  process.exit(errors ? 1 : 0);
})();
