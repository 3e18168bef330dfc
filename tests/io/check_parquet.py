#!/usr/bin/python3
"""Compares a reader's dump (DuckDB's from tests/io/read_parquet.js or the
Arrow Rust reader's from tests/io/read_parquet_arrow.js) of the files written
by tests/io/test_parquet.c with the values that test writes, computed here
from the row number the same way:
  check_parquet.py DUMP.json ROWS
The dump holds the full file (ROWS rows) and then the empty one."""
import base64
import json
import math
import struct
import sys

import numpy as np

INT64_MIN, INT64_MAX = -(2**63), 2**63 - 1


def int_of(r):
    if r == 1:
        return INT64_MIN
    if r == 2:
        return INT64_MAX
    return (r * 7919 - 50000) * (1 if r % 3 else -1)


def float_of(r):
    special = {3: math.nan, 4: -0.0, 5: math.inf, 6: -math.inf, 7: float(np.float32(1e-45))}
    return float(np.float32(special.get(r, np.float32(r) * np.float32(0.25) - np.float32(100.0))))


def list_of(r):
    n = 600 if r == 10 else r % 3
    return [float(np.float32(r) + np.float32(k) / np.float32(1024.0)) for k in range(n)]


def blob_of(r):
    n = 1536 * 1024 if r == 20 else (r * 13) % 500
    return bytes(((r * 31 + k * 7) & 0xFF) for k in range(n))


def path_of(r):
    return "" if r % 5 == 0 else f"fr\u00e4me_{r:06d}.png"


def num(v):
    if isinstance(v, str):
        return {"NaN": math.nan, "Infinity": math.inf, "-Infinity": -math.inf, "-0": -0.0}[v]
    return float(v)


def same_float(a, b):
    a, b = np.float32(num(a)), np.float32(b)
    return struct.pack("<f", a) == struct.pack("<f", b) or (math.isnan(a) and math.isnan(b))


def big(v):
    return int(v) if isinstance(v, str) else v


def main(argv):
    with open(argv[0]) as f:
        files = json.load(f)
    rows = int(argv[1])
    fails = []
    full, empty = files
    if full["kv"] != {"huggingface": '{"info": {}}', "second": "v\u00e4lue"}:
        fails.append(f"key-value metadata: {full['kv']}")
    want_types = {
        "duckdb": ["BIGINT", "FLOAT", "FLOAT[]", 'STRUCT("bytes" BLOB, "path" VARCHAR)'],
        "arrow": ["Int64", "Float32", "List<Float32>", "Struct<{bytes:Binary, path:Utf8}>"],
    }[full.get("reader", "duckdb")]
    if [c["type"] for c in full["columns"]] != want_types or [c["name"] for c in full["columns"]] != ["n", "x", "v", "b"]:
        fails.append(f"columns: {full['columns']}")
    if full["meta"]["num_rows"] != rows or full["meta"]["num_row_groups"] != (rows + 999) // 1000:
        fails.append(f"file metadata: {full['meta']}")
    if len(full["rows"]) != rows:
        fails.append(f"{len(full['rows'])} rows, expected {rows}")
    for r, row in enumerate(full["rows"][:rows]):
        if big(row["n"]) != int_of(r):
            fails.append(f"row {r}: n = {row['n']}, expected {int_of(r)}")
        if not same_float(row["x"], float_of(r)):
            fails.append(f"row {r}: x = {row['x']}, expected {float_of(r)}")
        want = list_of(r)
        got = row["v"]
        if got is None or len(got) != len(want) or not all(same_float(g, w) for g, w in zip(got, want)):
            fails.append(f"row {r}: v has {None if got is None else len(got)} items, expected {len(want)}")
        b = row["b"]
        if b is None or base64.b64decode(b["bytes"]["base64"]) != blob_of(r) or b["path"] != path_of(r):
            fails.append(f"row {r}: b differs (path {None if b is None else b['path']!r})")
        if len(fails) > 20:
            break
    if empty["rows"] or empty["meta"]["num_rows"] != 0:
        fails.append(f"the empty file: {empty['meta']}")
    for m in fails:
        print("FAIL:", m, file=sys.stderr)
    print(f"check_parquet: {len(fails)} failures")
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
