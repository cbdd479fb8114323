#!/usr/bin/env python3
"""Markdown tables for docs/results.md from wingman results directories.

usage: tools/seed_table.py RESULTS_ROOT VARIANT [VARIANT ...]
RESULTS_ROOT holds one results directory per seed (seed1/, seed2/, ...), each with one
subdirectory per variant as `wingman run` writes them (the runs/ folder of `wingman montecarlo`
has that layout). Prints, per variant, Table 4 and Table 5 totals for every seed and their mean,
min and max; with two or more variants, also on how many seeds the first variant has the lower
Table 4 total than each other one, per axis and on all six at once; and per seed, the share of
outliers among the tracked correspondences each variant's filter accepted (Table 3, every
channel but the cooperative one), the cooperative landmarks initialised and the outliers among
them, the axes of Tables 4 and 5 above the paper's multi-UAV row (docs/results.md), and the largest
distance of a landmark's final estimate from its truth (landmarks.csv).
"""
import csv
import json
import math
import statistics
import sys
from pathlib import Path


def cell(text):
    """A CSV value; an empty field is a value wingman does not have (NaN)."""
    return float(text) if text else float("nan")


def load(root, variant):
    runs = []
    for d in sorted(Path(root).iterdir(), key=lambda p: (len(p.name), p.name)):
        f = d / variant / "metrics.json"
        if f.is_file():
            m = json.loads(f.read_text())
            m["_worst_landmark_m"] = worst_landmark(d / variant / "landmarks.csv")
            runs.append((d.name, m))
    return runs


def worst_landmark(path):
    """Largest distance of a landmark's final estimate (or at removal) from its truth, m."""
    if not path.is_file():
        return float("nan")
    worst = 0.0
    with path.open() as f:
        for r in csv.DictReader(f):
            d = math.dist([cell(r[f"final_{a}"]) for a in "xyz"], [cell(r[f"truth_{a}"]) for a in "xyz"])
            worst = max(worst, d)
    return worst


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


# The paper's Table 4 totals, multi-UAV (Xh, Yh, Zh, X1, Y1, Z1) and Table 5 final.
PAPER_MULTI_T4 = [0.1221, 0.1676, 0.0468, 0.7621, 0.4847, 0.0755]
PAPER_MULTI_T5 = [0.4702, 0.4683, 1.2120]
AXES = ["Xh", "Yh", "Zh", "X1", "Y1", "Z1"]


def outliers(m):
    """(accepted outlier share of the tracked channels, cooperative accepted, cooperative outliers)."""
    tracked = [r for r in m["table3"] if r["channel"] != "cooperative"]
    acc = sum(r["accepted"] for r in tracked)
    bad = sum(r["outliers_accepted"] for r in tracked)
    coop = [r for r in m["table3"] if r["channel"] == "cooperative"]
    return (bad / acc if acc else float("nan"),
            coop[0]["accepted"] if coop else None, coop[0]["outliers_accepted"] if coop else None)


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
    print("\n#### per seed: outliers accepted, cooperative landmarks, above the paper's multi row\n")
    print("| seed | " + " | ".join(f"{v}: outliers accepted | {v}: cooperative (outliers) | {v}: Table 4 above paper | "
                                   f"{v}: Table 5 above paper | {v}: worst landmark (m)" for v in variants) + " |")
    print("|---" * (1 + 5 * len(variants)) + "|")
    by_seed = {v: dict(loaded[v]) for v in variants}
    for name, _ in loaded[variants[0]]:
        cells = []
        for v in variants:
            m = by_seed[v].get(name)
            if m is None:
                cells += ["—"] * 5
                continue
            share, coop, coop_bad = outliers(m)
            above4 = [a for a, x, ref in zip(AXES, table4_totals(m), PAPER_MULTI_T4) if x > ref]
            above5 = [a for a, x, ref in zip("XYZ", m["table5"]["total"]["final_mse"], PAPER_MULTI_T5)
                      if x is not None and x > ref]
            cells += [f"{100 * share:.2f} %", "—" if coop is None else f"{coop} ({coop_bad})",
                      ", ".join(above4) or "none", ", ".join(above5) or "none", f"{m['_worst_landmark_m']:.1f}"]
        print(f"| {name} | " + " | ".join(cells) + " |")
    for other in variants[1:]:
        per_axis, all_six, n = paired_counts(loaded[variants[0]], loaded[other])
        print(f"\n#### seeds where {variants[0]} has the lower Table 4 total than {other} (of {n})\n")
        print("| Xh | Yh | Zh | X1 | Y1 | Z1 | all six |")
        print("|---" * 7 + "|")
        print("| " + " | ".join(str(c) for c in per_axis + [all_six]) + " |")


if __name__ == "__main__":
    main()
