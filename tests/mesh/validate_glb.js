#!/usr/bin/env node
// Runs the Khronos glTF validator on one or more GLB/glTF files, prints every
// issue it reports and exits 1 if any file has errors (numErrors > 0).
//   node tests/mesh/validate_glb.js FILE...
// Exit codes: 0 valid, 1 errors found, 2 usage or unreadable file,
// 3 the gltf-validator package is not installed (run scripts/setup.sh).
'use strict';
const fs = require('fs');
const path = require('path');

function loadValidator() {
  // scripts/setup.sh installs the package under <source>/.tools
  const local = path.join(__dirname, '..', '..', '.tools', 'node_modules', 'gltf-validator');
  for (const where of [local, 'gltf-validator']) {
    try {
      return require(where);
    } catch (e) {
      // try the next place
    }
  }
  return null;
}

async function main() {
  const files = process.argv.slice(2);
  if (files.length === 0) {
    console.error('usage: node validate_glb.js FILE...');
    return 2;
  }
  const validator = loadValidator();
  if (!validator) {
    console.error('validate_glb: the npm package gltf-validator is not installed; ' +
                  'run scripts/setup.sh (it installs it into .tools/node_modules)');
    return 3;
  }
  const severity = ['error', 'warning', 'info', 'hint'];
  let status = 0;
  for (const file of files) {
    let bytes;
    try {
      bytes = new Uint8Array(fs.readFileSync(file));
    } catch (e) {
      console.error(`${file}: cannot read: ${e.message}`);
      status = Math.max(status, 2);
      continue;
    }
    let report;
    try {
      report = await validator.validateBytes(bytes, {uri: path.basename(file), maxIssues: 200});
    } catch (e) {
      console.error(`${file}: validator rejected the input: ${e}`);
      status = Math.max(status, 1);
      continue;
    }
    const is = report.issues;
    console.log(`${file}: validator ${report.validatorVersion}: ${is.numErrors} errors, ` +
                `${is.numWarnings} warnings, ${is.numInfos} infos, ${is.numHints} hints`);
    for (const m of is.messages) {
      const where = m.pointer !== undefined ? m.pointer
                                            : (m.offset !== undefined ? `@${m.offset}` : "");
      console.log(`  ${severity[m.severity] || m.severity} ${m.code} ${where}: ${m.message}`);
    }
    if (is.numErrors > 0) status = Math.max(status, 1);
  }
  return status;
}

main().then((code) => process.exit(code), (e) => {
  console.error(`validate_glb: ${e && e.stack ? e.stack : e}`);
  process.exit(2);
});
