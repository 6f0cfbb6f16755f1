// Runs the Khronos glTF validator (the npm package gltf-validator, installed by
// `scripts/setup.sh test` into .node/) over each file named on the command line and prints one
// JSON line per file: {"file", "errors", "warnings", "infos", "messages": [...]}. Exits 0 when
// every file was read; the caller judges the counts (tests/test_gltf_validator.py).
"use strict";
const fs = require("fs");
const path = require("path");
const validator = require(path.join(__dirname, "..", ".node", "node_modules", "gltf-validator"));

async function main(files) {
  for (const file of files) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
      uri: path.basename(file),
      maxIssues: 0, // every issue
    });
    const issues = report.issues;
    console.log(JSON.stringify({
      file,
      errors: issues.numErrors,
      warnings: issues.numWarnings,
      infos: issues.numInfos,
      messages: issues.messages.map((m) => ({code: m.code, severity: m.severity,
                                            message: m.message, pointer: m.pointer})),
    }));
  }
}

main(process.argv.slice(2)).catch((error) => {
  console.error(String(error));
  process.exit(2);
});
