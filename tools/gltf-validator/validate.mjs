// Validates a .gltf or .glb with the Khronos glTF validator and prints its issue counts and
// messages. Exit status: 0 without errors, 1 with errors, 2 when the file cannot be read.
// Usage: node tools/gltf-validator/validate.mjs FILE
import fs from "node:fs";
import path from "node:path";
import validator from "gltf-validator";

const file = process.argv[2];
if (!file) {
  console.error("usage: node validate.mjs FILE.gltf|FILE.glb");
  process.exit(2);
}
let bytes;
try {
  bytes = fs.readFileSync(file);
} catch (error) {
  console.error(`${file}: ${error.message}`);
  process.exit(2);
}
const report = await validator.validateBytes(new Uint8Array(bytes), {
  uri: path.basename(file),
  maxIssues: 1000,
  externalResourceFunction: (uri) =>
    new Promise((resolve, reject) => {
      fs.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)), (err, data) => (err ? reject(err.toString()) : resolve(data)));
    }),
});
const issues = report.issues;
console.log(`errors=${issues.numErrors} warnings=${issues.numWarnings} infos=${issues.numInfos} hints=${issues.numHints}`);
for (const m of issues.messages) console.log(`[${m.severity}] ${m.code}: ${m.message} @ ${m.pointer ?? ""}`);
process.exit(issues.numErrors > 0 ? 1 : 0);
