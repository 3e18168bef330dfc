#!/usr/bin/env node
// Reads Parquet files with the Apache Arrow Rust reader (npm parquet-wasm,
// arrow-rs's parquet crate built for WebAssembly) and the Arrow JavaScript
// library (npm apache-arrow), a second implementation independent of both
// hearth's writer and DuckDB, and dumps what it finds in the JSON form
// tests/io/read_parquet.js writes:
//   node tests/io/read_parquet_arrow.js OUT.json FILE.parquet...
// OUT.json: [{file, reader: "arrow", kv: {key: value}, meta: {num_rows,
// num_row_groups}, columns: [{name, type}], rows: [{col: value}]}] with
// types as Arrow names them (Int64, Float32, List<Float32>, Struct<{...}>),
// 64-bit integers as numbers (strings past 2^53), binary as {"base64": ...},
// structs as objects, lists as arrays, NaN/Infinity/-0 as strings.
// Exit codes: 0 read, 1 a file could not be read, 2 usage,
// 3 parquet-wasm or apache-arrow is not installed (run scripts/setup.sh).
'use strict';
const fs = require('fs');
const path = require('path');

function load(name, sub) {
  // scripts/setup.sh installs the packages under <source>/.tools
  const local = path.join(__dirname, '..', '..', '.tools', 'node_modules', name);
  for (const where of [local + (sub || ''), name + (sub || '')]) {
    try {
      return require(where);
    } catch (e) {
      // try the next place
    }
  }
  return null;
}

function plain(v) {
  if (v === null || v === undefined) return null;
  if (typeof v === 'bigint') return Number.isSafeInteger(Number(v)) ? Number(v) : v.toString();
  if (typeof v === 'number') {
    if (Number.isNaN(v)) return 'NaN';
    if (v === Infinity) return 'Infinity';
    if (v === -Infinity) return '-Infinity';
    if (Object.is(v, -0)) return '-0';
    return v;
  }
  if (typeof v !== 'object') return v;
  if (v instanceof Uint8Array) return { base64: Buffer.from(v).toString('base64') };
  if (typeof v.toArray === 'function' && !(typeof v.toJSON === 'function' && v.constructor.name.includes('Row')))
    return Array.from(v.toArray(), plain);
  if (typeof v.toJSON === 'function') {
    const o = {};
    const j = v.toJSON();
    for (const k of Object.keys(j)) o[k] = plain(j[k]);
    return o;
  }
  return String(v);
}

async function main() {
  const args = process.argv.slice(2);
  if (args.length < 2) {
    console.error('usage: node read_parquet_arrow.js OUT.json FILE.parquet...');
    return 2;
  }
  const pw = load('parquet-wasm', '/node/parquet_wasm.js');
  const arrow = load('apache-arrow');
  if (!pw || !arrow) {
    console.error('read_parquet_arrow: the npm packages parquet-wasm and apache-arrow are not installed; ' +
                  'run scripts/setup.sh (it installs them into .tools/node_modules)');
    return 3;
  }
  const out = [];
  for (const file of args.slice(1)) {
    try {
      const bytes = new Uint8Array(fs.readFileSync(file));
      const pf = await pw.ParquetFile.fromFile(new Blob([bytes]));
      const md = pf.metadata();
      const fmd = md.fileMetadata();
      const kv = {};
      for (const [k, v] of fmd.keyValueMetadata()) kv[k] = v;
      const table = arrow.tableFromIPC(pw.readParquet(bytes).intoIPCStream());
      const fields = table.schema.fields;
      const rows = [];
      for (let i = 0; i < table.numRows; i++) {
        const row = table.get(i);
        const o = {};
        for (const f of fields) o[f.name] = plain(row[f.name]);
        rows.push(o);
      }
      out.push({
        file,
        reader: 'arrow',
        kv,
        meta: { num_rows: Number(fmd.numRows()), num_row_groups: md.numRowGroups() },
        columns: fields.map((f) => ({ name: f.name, type: f.type.toString() })),
        rows,
      });
    } catch (e) {
      console.error(`read_parquet_arrow: ${file}: ${e.message}`);
      return 1;
    }
  }
  fs.writeFileSync(args[0], JSON.stringify(out));
  return 0;
}

main().then((code) => process.exit(code), (e) => { console.error(e); process.exit(1); });
