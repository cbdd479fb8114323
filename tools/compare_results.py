#!/usr/bin/env python3
"""Compare two Wingman results trees, timings aside.

    tools/compare_results.py A B

A and B are results directories (`wingman run --out`) or trees of them (as written by
tools/regress_scenes.sh). Every steps.csv, landmarks.csv and metrics.json under A is compared
with the file at the same relative path under B: CSVs row by row, without the per-stage timing
columns (t_*_ms), an empty field and "nan" both meaning no value; metrics.json key by key, without wall times, timings, the software version and
the scenario's path. Prints one line per results directory ("identical" or the first difference,
named by file, row or key path) and exits 1 when anything differs or is missing.
"""
import csv
import json
import os
import sys

FILES = ("steps.csv", "landmarks.csv", "metrics.json")
IGNORED_KEYS = {"wall_time_s", "timings_ms", "software_version", "scenario_path", "detect_busy_ms",
                "real_time_factor", "renderer", "path"}


def is_ignored_key(key):
    return key in IGNORED_KEYS or key.endswith("_ms") or key.endswith("_ms_per_step")


def is_timing_column(name):
    return name.startswith("t_") and name.endswith("_ms")


def missing(cell):
    """An absent value: wingman writes an empty field; older versions wrote nan."""
    return cell == "" or cell.lower() == "nan"


def compare_csv(a, b):
    with open(a, newline="") as fa, open(b, newline="") as fb:
        ra, rb = list(csv.reader(fa)), list(csv.reader(fb))
    if not ra or not rb:
        return None if ra == rb else "one file is empty"
    keep = [i for i, h in enumerate(ra[0]) if not is_timing_column(h)]
    if ra[0] != rb[0]:
        return f"header differs: {ra[0]} vs {rb[0]}"
    if len(ra) != len(rb):
        return f"{len(ra) - 1} rows vs {len(rb) - 1}"
    for r, (x, y) in enumerate(zip(ra, rb)):
        for i in keep:
            if x[i] != y[i] and not (missing(x[i]) and missing(y[i])):
                return f"row {r}, column {ra[0][i]}: {x[i]} vs {y[i]}"
    return None


def compare_json(x, y, path=""):
    if isinstance(x, dict) and isinstance(y, dict):
        for k in sorted(set(x) | set(y)):
            if is_ignored_key(k):
                continue
            if k not in x or k not in y:
                return f"{path}.{k}: only in {'B' if k not in x else 'A'}"
            d = compare_json(x[k], y[k], f"{path}.{k}")
            if d:
                return d
        return None
    if isinstance(x, list) and isinstance(y, list):
        if len(x) != len(y):
            return f"{path}: {len(x)} items vs {len(y)}"
        for i, (p, q) in enumerate(zip(x, y)):
            d = compare_json(p, q, f"{path}[{i}]")
            if d:
                return d
        return None
    return None if x == y else f"{path}: {x!r} vs {y!r}"


def compare_file(a, b):
    if not os.path.exists(b):
        return "missing in B"
    if a.endswith(".csv"):
        return compare_csv(a, b)
    with open(a) as fa, open(b) as fb:
        return compare_json(json.load(fa), json.load(fb))


def main():
    if len(sys.argv) != 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    root_a, root_b = sys.argv[1], sys.argv[2]
    dirs = {}
    for d, _, files in os.walk(root_a):
        for f in files:
            if f in FILES:
                dirs.setdefault(os.path.relpath(d, root_a), []).append(f)
    if not dirs:
        print(f"{root_a}: no results found", file=sys.stderr)
        return 2
    bad = 0
    for rel in sorted(dirs):
        diffs = []
        for f in sorted(dirs[rel]):
            d = compare_file(os.path.join(root_a, rel, f), os.path.join(root_b, rel, f))
            if d:
                diffs.append(f"{f}: {d}")
        bad += bool(diffs)
        print(f"{rel}: " + ("identical" if not diffs else "DIFFERS: " + "; ".join(diffs)))
    for d, _, files in os.walk(root_b):
        rel = os.path.relpath(d, root_b)
        if any(f in FILES for f in files) and rel not in dirs:
            print(f"{rel}: only in B")
            bad += 1
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
