#!/usr/bin/env python3
"""Markdown tables for docs/results.md from wingman results directories.

usage: tools/seed_table.py RESULTS_ROOT VARIANT [VARIANT ...]
RESULTS_ROOT holds one results directory per seed (seed1/, seed2/, ...), each with one
subdirectory per variant as `wingman run` writes them (the runs/ folder of `wingman montecarlo`
has that layout). Prints, per variant, Table 4 and Table 5 totals for every seed and their mean,
min and max; with two or more variants, also on how many seeds the first variant has the lower
Table 4 total than each other one, per axis and on all six at once.
"""
import json
import statistics
import sys
from pathlib import Path


def load(root, variant):
    runs = []
    for d in sorted(Path(root).iterdir(), key=lambda p: (len(p.name), p.name)):
        f = d / variant / "metrics.json"
        if f.is_file():
            runs.append((d.name, json.loads(f.read_text())))
    return runs


def table4_totals(m):
    t4 = m["table4"]["total"]
    return t4["lead"]["mse"] + t4["uav1"]["mse"]


def paired_counts(first_runs, other_runs):
    """Seeds where the first variant has the lower Table 4 total: per axis, all six, seeds."""
    a, b = dict(first_runs), dict(other_runs)
    seeds = [s for s in a if s in b]
    wins = [[x < y for x, y in zip(table4_totals(a[s]), table4_totals(b[s]))] for s in seeds]
    per_axis = [sum(col) for col in zip(*wins)] if wins else [0] * 6
    return per_axis, sum(all(w) for w in wins), len(seeds)


def row(name, values):
    return "| " + name + " | " + " | ".join(f"{v:.4f}" for v in values) + " |"


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    root, variants = sys.argv[1], sys.argv[2:]
    loaded = {}
    for variant in variants:
        runs = loaded[variant] = load(root, variant)
        if not runs:
            sys.exit(f"no {variant}/metrics.json under {root}")
        print(f"\n#### {variant}: Table 4 totals (MSE, m²) and Table 5 totals over {len(runs)} seeds\n")
        print("| seed | Xh | Yh | Zh | X1 | Y1 | Z1 | lm X | lm Y | lm Z | lm init X | lm init Y | lm init Z |")
        print("|---" * 13 + "|")
        table = []
        for name, m in runs:
            t5 = m["table5"]["total"]
            vals = table4_totals(m) + t5["final_mse"] + t5["init_mse"]
            vals = [float("nan") if v is None else v for v in vals]
            table.append(vals)
            print(row(name, vals))
        cols = list(zip(*table))
        print(row("**mean**", [statistics.fmean(c) for c in cols]))
        print(row("min", [min(c) for c in cols]))
        print(row("max", [max(c) for c in cols]))
    for other in variants[1:]:
        per_axis, all_six, n = paired_counts(loaded[variants[0]], loaded[other])
        print(f"\n#### seeds where {variants[0]} has the lower Table 4 total than {other} (of {n})\n")
        print("| Xh | Yh | Zh | X1 | Y1 | Z1 | all six |")
        print("|---" * 7 + "|")
        print("| " + " | ".join(str(c) for c in per_axis + [all_six]) + " |")


if __name__ == "__main__":
    main()
