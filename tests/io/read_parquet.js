#!/usr/bin/env node
// Reads Parquet files with DuckDB (npm @duckdb/node-api, an implementation
// independent of hearth's writer) and dumps what it finds as JSON:
//   node tests/io/read_parquet.js OUT.json FILE.parquet...
// OUT.json: [{file, schema: [parquet_schema rows], kv: {key: value},
// meta: parquet_file_metadata, columns: [{name, type}], rows: [{col: value}]}]
// with BIGINT as numbers (strings past 2^53), BLOB as {"base64": ...},
// structs as objects, lists as arrays, NaN/Infinity/-0 as strings.
// Exit codes: 0 read, 1 a file could not be read, 2 usage,
// 3 the @duckdb/node-api package is not installed (run scripts/setup.sh).
'use strict';
const fs = require('fs');
const path = require('path');

function loadDuckDB() {
  // scripts/setup.sh installs the package under <source>/.tools
  const local = path.join(__dirname, '..', '..', '.tools', 'node_modules', '@duckdb', 'node-api');
  for (const where of [local, '@duckdb/node-api']) {
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
  const kind = v.constructor && v.constructor.name;
  if (kind === 'DuckDBBlobValue') return { base64: Buffer.from(v.bytes).toString('base64') };
  if (kind === 'DuckDBStructValue') {
    const o = {};
    for (const k of Object.keys(v.entries)) o[k] = plain(v.entries[k]);
    return o;
  }
  if (kind === 'DuckDBListValue' || kind === 'DuckDBArrayValue') return v.items.map(plain);
  if (Buffer.isBuffer(v) || v instanceof Uint8Array) return Buffer.from(v).toString();
  return String(v);
}

function quote(p) {
  return "'" + p.replace(/'/g, "''") + "'";
}

async function rows(conn, sql) {
  const r = await conn.runAndReadAll(sql);
  const names = r.columnNames();
  return r.getRows().map((row) => {
    const o = {};
    row.forEach((v, k) => { o[names[k]] = plain(v); });
    return o;
  });
}

async function main() {
  const args = process.argv.slice(2);
  if (args.length < 2) {
    console.error('usage: node read_parquet.js OUT.json FILE.parquet...');
    return 2;
  }
  const duckdb = loadDuckDB();
  if (!duckdb) {
    console.error('read_parquet: the npm package @duckdb/node-api is not installed; ' +
                  'run scripts/setup.sh (it installs it into .tools/node_modules)');
    return 3;
  }
  const inst = await duckdb.DuckDBInstance.create(':memory:');
  const conn = await inst.connect();
  const out = [];
  for (const file of args.slice(1)) {
    try {
      const q = quote(file);
      const kv = {};
      const text = (v) => (v && v.base64 !== undefined ? Buffer.from(v.base64, 'base64').toString('utf8') : v);
      for (const r of await rows(conn, `SELECT key, value FROM parquet_kv_metadata(${q})`)) kv[text(r.key)] = text(r.value);
      const res = await conn.runAndReadAll(`SELECT * FROM read_parquet(${q})`);
      const names = res.columnNames(), types = res.columnTypes().map((t) => t.toString());
      const data = res.getRows().map((row) => {
        const o = {};
        row.forEach((v, k) => { o[names[k]] = plain(v); });
        return o;
      });
      out.push({
        file,
        schema: await rows(conn, `SELECT * FROM parquet_schema(${q})`),
        kv,
        meta: (await rows(conn, `SELECT * FROM parquet_file_metadata(${q})`))[0],
        columns: names.map((n, k) => ({ name: n, type: types[k] })),
        rows: data,
      });
    } catch (e) {
      console.error(`read_parquet: ${file}: ${e.message}`);
      return 1;
    }
  }
  fs.writeFileSync(args[0], JSON.stringify(out));
  return 0;
}

main().then((code) => process.exit(code), (e) => { console.error(e); process.exit(1); });
