// Validates .glb files with the Khronos glTF validator (npm gltf-validator).
// Usage: node validate_gltf.js FILE.glb [...]
// Prints each file's error and warning counts; exits 1 when any file has an
// error (or cannot be read), 2 when the validator is not installed.
'use strict';
const fs = require('fs');
const path = require('path');

let validator;
try {
  validator = require(path.join(__dirname, 'node_modules', 'gltf-validator'));
} catch (e) {
  console.error('gltf-validator is not installed: run scripts/install-deps.sh (npm install in tests/js)');
  process.exit(2);
}

async function validate(file) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const report = await validator.validateBytes(bytes, {maxIssues: 20});
  const n = report.issues;
  console.log(`${file}: ${n.numErrors} errors, ${n.numWarnings} warnings, ${n.numInfos} infos`);
  for (const m of n.messages) {
    if (m.severity === 0) console.log(`  error ${m.code}: ${m.message} (${m.pointer || ''})`);
  }
  return n.numErrors;
}

(async () => {
  const files = process.argv.slice(2);
  if (files.length === 0) {
    console.error('usage: node validate_gltf.js FILE.glb [...]');
    process.exit(2);
  }
  let errors = 0;
  for (const f of files) {
    try {
      errors += await validate(f);
    } catch (e) {
      console.log(`${f}: cannot validate: ${e.message || e}`);
      errors += 1;
    }
  }
  process.exit(errors > 0 ? 1 : 0);
})();
