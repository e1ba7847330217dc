// Validate a .glb/.gltf with the Khronos glTF validator (npm gltf-validator, installed by `make setup`
// into .venv/node): node tests/gltf_validate.js FILE -> prints the validation report as JSON.
const fs = require("fs");
const path = require("path");
const validator = require(path.resolve(__dirname, "..", ".venv", "node", "node_modules", "gltf-validator"));

const file = process.argv[2];
validator.validateBytes(new Uint8Array(fs.readFileSync(file)), { uri: path.basename(file), maxIssues: 1000 })
  .then((report) => { console.log(JSON.stringify(report)); })
  .catch((error) => { console.error(String(error)); process.exit(2); });
