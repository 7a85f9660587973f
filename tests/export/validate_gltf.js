// Runs the Khronos glTF-Validator (npm package gltf-validator) on each file given; prints one JSON line per
// file: {"file", "errors", "warnings", "infos", "hints", "messages"}.
const fs = require("fs");
const validator = require("gltf-validator");
(async () => {
  for (const file of process.argv.slice(2)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)));
    const i = report.issues;
    console.log(JSON.stringify({file, errors: i.numErrors, warnings: i.numWarnings, infos: i.numInfos,
                                hints: i.numHints, messages: i.messages.slice(0, 20)}));
  }
})();
