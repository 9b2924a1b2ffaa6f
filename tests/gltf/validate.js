// Runs the Khronos glTF validator (npm gltf-validator) on one file; prints the issue counts and
// every error/warning message; exit 0 when there are no errors, 1 otherwise, 77 when the
// validator package is not installed (npm install --prefix tests/gltf).
'use strict';
const fs = require('fs');
const path = require('path');
let validator;
try {
  validator = require(path.join(__dirname, 'node_modules', 'gltf-validator'));
} catch (e) {
  console.log('gltf-validator not installed');
  process.exit(77);
}
const file = process.argv[2];
const data = new Uint8Array(fs.readFileSync(file));
validator.validateBytes(data, {
  uri: path.basename(file),
  maxIssues: 100,
  externalResourceFunction: (uri) => new Promise((resolve, reject) => {
    fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)), (err, d) => err ? reject(err.toString()) : resolve(new Uint8Array(d)));
  }),
}).then((report) => {
  const i = report.issues;
  console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints`);
  for (const m of i.messages) if (m.severity <= 1) console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} ${m.pointer || ''}: ${m.message}`);
  process.exit(i.numErrors === 0 ? 0 : 1);
}, (err) => { console.log(`validator failed: ${err}`); process.exit(1); });
