// The Khronos glTF validator on files Marionette wrote:
//
//     npm install gltf-validator        (once, anywhere; NODE_PATH can point at it)
//     marionette export assets/default_scene.ron --out /tmp/scene.glb
//     node scripts/validate_gltf.js /tmp/scene.glb
//
// Prints the counts of errors, warnings, infos and hints, and the first messages; exits 1
// when there is an error.
const validator = require('gltf-validator');
const fs = require('fs');

(async () => {
  let failed = false;
  for (const file of process.argv.slice(2)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)));
    const i = report.issues;
    console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints`);
    for (const m of i.messages.slice(0, 12)) console.log(`  ${m.severity} ${m.code} ${m.pointer || ''}: ${m.message}`);
    failed ||= i.numErrors > 0;
  }
  process.exit(failed ? 1 : 0);
})();
