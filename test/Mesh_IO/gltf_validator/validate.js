// Validates one .gltf or .glb file with the Khronos glTF validator and prints one line:
//   errors=<n> warnings=<n> infos=<n> hints=<n>
// followed by one line per error or warning ("<severity> <code> <pointer>: <message>").
// Exit status: 0 when the file could be validated (whatever it holds), 2 when it could not.
'use strict';
const fs = require('fs');
const path = require('path');

let validator;
try {
  validator = require(path.join(__dirname, 'node_modules', 'gltf-validator'));
} catch (e) {
  console.error('gltf-validator is not installed: npm install in ' + __dirname);
  process.exit(3);
}
const file = process.argv[2];
if (!file) {
  console.error('usage: node validate.js FILE.gltf|FILE.glb');
  process.exit(2);
}
const full = path.resolve(file);
validator.validateBytes(new Uint8Array(fs.readFileSync(full)), {
  uri: path.basename(full),
  maxIssues: 1000,
  externalResourceFunction: (uri) => new Promise((resolve, reject) => {
    fs.readFile(path.resolve(path.dirname(full), decodeURIComponent(uri)), (err, data) => {
      if (err) reject(err.toString()); else resolve(data);
    });
  }),
}).then((report) => {
  const n = report.issues;
  console.log(`errors=${n.numErrors} warnings=${n.numWarnings} infos=${n.numInfos} hints=${n.numHints}`);
  const names = ['error', 'warning', 'info', 'hint'];
  for (const m of n.messages) {
    console.log(`${names[m.severity]} ${m.code} ${m.pointer || ''}: ${m.message}`);
  }
}, (error) => {
  console.error(String(error));
  process.exit(2);
});
