"""Reads an MBTiles file with Python's own sqlite3 module (an SQLite independent of the
one tinsmith bundles) and prints what it found as JSON on stdout.

Usage: .venv/bin/python3 tests/oracles/mbtiles_read.py FILE

Output: {"sqlite_version": str, "application_id": int, "integrity": str,
         "tables": {name: [[column, declared type], ...]},
         "indexes": {table: [{"name": str, "unique": bool, "columns": [str, ...]}]},
         "metadata": {name: value}, "metadata_rows": int,
         "tiles": [[zoom_level, tile_column, tile_row, hex of tile_data], ...]}
The file is opened read-only (a URI with mode=ro): reading it must not change it.
"""
import json
import pathlib
import sqlite3
import sys


def main():
    uri = pathlib.Path(sys.argv[1]).resolve().as_uri() + "?mode=ro"
    db = sqlite3.connect(uri, uri=True)
    out = {"sqlite_version": sqlite3.sqlite_version}
    out["application_id"] = db.execute("PRAGMA application_id").fetchone()[0]
    out["integrity"] = db.execute("PRAGMA integrity_check").fetchone()[0]
    tables = [r[0] for r in db.execute(
        "SELECT name FROM sqlite_master WHERE type IN ('table', 'view') ORDER BY name")]
    out["tables"] = {t: [[c[1], c[2]] for c in db.execute(f"PRAGMA table_info('{t}')")]
                     for t in tables}
    out["indexes"] = {}
    for t in tables:
        indexes = []
        for _, name, unique, *_ in db.execute(f"PRAGMA index_list('{t}')"):
            columns = [c[2] for c in db.execute(f"PRAGMA index_info('{name}')")]
            indexes.append({"name": name, "unique": bool(unique), "columns": columns})
        out["indexes"][t] = indexes
    rows = db.execute("SELECT name, value FROM metadata").fetchall()
    out["metadata_rows"] = len(rows)
    out["metadata"] = dict(rows)
    out["tiles"] = [[z, x, y, bytes(data).hex()] for z, x, y, data in db.execute(
        "SELECT zoom_level, tile_column, tile_row, tile_data FROM tiles "
        "ORDER BY zoom_level, tile_column, tile_row")]
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
