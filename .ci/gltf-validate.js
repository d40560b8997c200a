// Validates glTF binaries with the Khronos glTF-Validator; exits 1 on any error or warning.
// Usage: node .ci/gltf-validate.js FILE.glb ...
const validator = require('gltf-validator');
const fs = require('fs');
(async () => {
  let bad = 0;
  for (const file of process.argv.slice(2)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)));
    const { numErrors, numWarnings, numInfos } = report.issues;
    console.log(`${file}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos`);
    for (const m of report.issues.messages) console.log(`  ${m.code}: ${m.message} at ${m.pointer}`);
    if (numErrors + numWarnings > 0) bad++;
  }
  process.exit(bad ? 1 : 0);
})();
