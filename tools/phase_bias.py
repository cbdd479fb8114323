#!/usr/bin/env python3
"""Systematic error per phase over seeds, from wingman results directories.

usage: tools/phase_bias.py RESULTS_ROOT VARIANT [VARIANT ...]
RESULTS_ROOT holds one results directory per seed (seed1/, seed2/, ...), each with one
subdirectory per variant (the runs/ folder of `wingman montecarlo` has that layout).

Prints, per variant and phase, for the lead and Quad 1 (uav1) on each axis: the mean over seeds
of the run's mean signed error (estimate minus truth, steps.csv), the standard deviation of that
per-seed mean, the mean MSE, and the filter's own σ there (the root of the mean of
`<agent>_s<axis>` squared, over every step of every seed) beside the RMS error it describes.
A mean far from zero against its spread is an error every seed shares: a bias, not drift that
one draw decides. Then the median signed error of the landmarks
initialised in each phase (landmarks.csv), at initialisation and at the end, per axis: a
landmark map that sits too near the cameras shows as a positive z there. Between the two, per
phase and agent: how far the estimate trails the truth in time, its speed's relative error, and
how much its x error changed inside the phase (a drift, against an offset carried in).
"""
import csv
import math
import statistics
import sys
from pathlib import Path


def cell(text):
    """A CSV value; an empty field is a value wingman does not have (NaN)."""
    return float(text) if text else float("nan")


def seed_dirs(root, variant):
    dirs = [d / variant for d in Path(root).iterdir() if (d / variant / "steps.csv").is_file()]
    return sorted(dirs, key=lambda p: (len(p.parent.name), p.parent.name))


def read_steps(d):
    """steps.csv's rows after the known initial state (k = 0)."""
    with (d / "steps.csv").open() as f:
        return [r for r in csv.DictReader(f) if r["k"] != "0"]


def agent_table(runs, agents=("lead", "uav1")):
    per = {}  # (phase, agent, axis) -> [(mean signed error, mse, mean σ²) per seed]
    for rows in runs:
        acc = {}
        for r in rows:
            for a in agents:
                for ax in "xyz":
                    e = cell(r[f"{a}_p{ax}_est"]) - cell(r[f"{a}_p{ax}_true"])
                    sig = cell(r[f"{a}_s{ax}"])
                    s = acc.setdefault((r["phase"], a, ax), [0, 0.0, 0.0, 0.0])
                    s[0] += 1
                    s[1] += e
                    s[2] += e * e
                    s[3] += sig * sig
        for key, (n, se, se2, ss2) in acc.items():
            per.setdefault(key, []).append((se / n, se2 / n, ss2 / n))
    return per


def motion_table(runs, agents=("lead", "uav1")):
    """Per seed, phase and agent: the horizontal lag tau that best explains the position error as
    -tau v (least squares over x and y), the speed's relative error (the velocity error along the
    true velocity over |v|^2), and how much the x error changed from the phase's first step to its
    last. An estimate that trails the truth has tau > 0; a drift inside a phase shows in the change."""
    per = {}  # (phase, agent) -> [(tau, speed error, x change) per seed]
    for rows in runs:
        acc, ends = {}, {}
        for r in rows:
            for a in agents:
                s = acc.setdefault((r["phase"], a), [0.0, 0.0, 0.0])
                for ax in "xy":
                    v = cell(r[f"{a}_v{ax}_true"])
                    s[0] += (cell(r[f"{a}_p{ax}_est"]) - cell(r[f"{a}_p{ax}_true"])) * v
                    s[1] += (cell(r[f"{a}_v{ax}_est"]) - v) * v
                    s[2] += v * v
                ex = cell(r[f"{a}_px_est"]) - cell(r[f"{a}_px_true"])
                ends.setdefault((r["phase"], a), [ex, ex])[1] = ex
        for key, (ep, ev, vv) in acc.items():
            first, last = ends[key]
            per.setdefault(key, []).append((-ep / vv, ev / vv, last - first))
    return per


def landmark_table(dirs):
    per = {}  # phase -> {"init": [[x], [y], [z]], "final": ...}
    for d in dirs:
        path = d / "landmarks.csv"
        if not path.is_file():
            continue
        with path.open() as f:
            for r in csv.DictReader(f):
                t = per.setdefault(r["init_phase"], {"init": [[], [], []], "final": [[], [], []]})
                for i, ax in enumerate("xyz"):
                    truth = cell(r[f"truth_{ax}"])
                    for when in ("init", "final"):
                        v = cell(r[f"{when}_{ax}"])
                        if math.isfinite(v):
                            t[when][i].append(v - truth)
    return per


def main(argv):
    if len(argv) < 3:
        sys.exit(__doc__)
    root = argv[1]
    if not Path(root).is_dir():
        sys.exit(f"{root}: not a directory")
    for variant in argv[2:]:
        dirs = seed_dirs(root, variant)
        if not dirs:
            sys.exit(f"{root}: no seed directory with {variant}/steps.csv")
        print(f"#### {variant}: signed error per phase over {len(dirs)} seeds (m; MSE m²)\n")
        print("| phase | agent | axis | mean signed error | sd over seeds | mean MSE | RMS error | filter σ |")
        print("|---|---|---|---|---|---|---|---|")
        runs = [read_steps(d) for d in dirs]
        per = agent_table(runs)
        for (phase, agent, axis), v in sorted(per.items()):
            means = [m for m, _, _ in v]
            sd = statistics.pstdev(means) if len(means) > 1 else float("nan")
            mse = statistics.fmean(s for _, s, _ in v)
            sigma = math.sqrt(statistics.fmean(s for _, _, s in v))
            print(f"| {phase} | {agent} | {axis} | {statistics.fmean(means):+.3f} | {sd:.3f} | {mse:.4f} "
                  f"| {math.sqrt(mse):.3f} | {sigma:.3f} |")
        print(f"\n#### {variant}: lag, speed and drift per phase, mean over seeds (range)\n")
        print("| phase | agent | lag τ (s) | speed error | x error change over the phase (m) |")
        print("|---|---|---|---|---|")
        for (phase, agent), v in sorted(motion_table(runs).items()):
            cells = []
            for i, fmt in enumerate(("{:+.2f}", "{:+.2%}", "{:+.3f}")):
                col = [x[i] for x in v]
                cells.append(f"{fmt.format(statistics.fmean(col))} "
                             f"({fmt.format(min(col))} to {fmt.format(max(col))})")
            print(f"| {phase} | {agent} | " + " | ".join(cells) + " |")
        lm = landmark_table(dirs)
        if lm:
            print(f"\n#### {variant}: landmarks' median signed error by the phase they were initialised in (m)\n")
            print("| phase | landmarks | init x | init y | init z | final x | final y | final z |")
            print("|---|---|---|---|---|---|---|---|")
            for phase, t in sorted(lm.items()):
                med = [statistics.median(l) if l else float("nan") for l in t["init"] + t["final"]]
                print(f"| {phase} | {len(t['init'][0])} | " + " | ".join(f"{m:+.3f}" for m in med) + " |")
        print()


if __name__ == "__main__":
    main(sys.argv)
