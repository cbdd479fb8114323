#!/usr/bin/env python3
"""Runs a rendered scenario at its defaults over several seeds and summarises consistency, accuracy
and speed (docs/studies/default-noise.md).

usage: tools/defaults_study.py WINGMAN SCENARIO OUTDIR [--seeds 1 2 3] [--strip-estimator]
       [--set KEY=VALUE ...]
--strip-estimator runs a copy of SCENARIO without its `estimator:` section (and without the
estimator keys of its variants), so that every estimator setting takes its default; --set
overrides a top-level section's key in the copy (e.g. --set world.image.msaa=1). Prints one row
per seed and variant: NEES mean / dof, the lead's Table 4 MSE (x+y+z, m^2), the rendering step's
median and worst (ms), the worst step over the median, wall seconds, real-time factor, and the
consistency blocks outside their band. Refuses an OUTDIR that exists.
"""
import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import yaml


def set_key(doc, dotted, value):
    keys = dotted.split(".")
    node = doc
    for k in keys[:-1]:
        node = node.setdefault(k, {})
    node[keys[-1]] = yaml.safe_load(value)


def prepare(scenario, out, strip, sets):
    doc = yaml.safe_load(Path(scenario).read_text())
    if strip:
        doc.pop("estimator", None)
        for v in doc.get("variants", []) or []:
            v.pop("estimator", None)
    for s in sets:
        key, _, value = s.partition("=")
        set_key(doc, key, value)
    copy = out / Path(scenario).name
    # Relative asset paths resolve next to the scenario: keep the copy's assets reachable.
    doc.setdefault("world", {})
    copy.write_text(yaml.safe_dump(doc, sort_keys=False))
    return copy


def summarise(run_dir, duration, wall):
    m = json.loads((run_dir / "metrics.json").read_text())
    lead = sum(m["table4"]["total"]["lead"]["mse"])
    render = m["timings_ms"].get("render", {})
    med, worst = render.get("median") or float("nan"), render.get("max") or float("nan")
    nees, dof = m["nees"]["mean"], m["nees"]["dof"]
    return (f"{nees / dof:.2f} | {lead:.4f} | {med:.0f} | {worst:.0f} | {worst / med:.1f} | {wall:.0f} | "
            f"{duration / wall:.2f} | {len(m['consistency']['outside_band'])} of {m['consistency']['blocks_checked']}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("wingman")
    ap.add_argument("scenario")
    ap.add_argument("outdir")
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--strip-estimator", action="store_true")
    ap.add_argument("--set", action="append", default=[])
    a = ap.parse_args()
    out = Path(a.outdir)
    if out.exists():
        sys.exit(f"defaults_study: {out} exists; choose a new directory")
    out.mkdir(parents=True)
    scenario = Path(a.scenario).resolve()
    copy = prepare(scenario, out, a.strip_estimator, a.set)
    # Run from the scenario's own folder so that relative trajectory files still resolve.
    duration = yaml.safe_load(copy.read_text()).get("duration", 210)
    print("seed | NEES/dof | lead MSE | render median | render worst | worst/median | wall s | x real time | outside band")
    for seed in a.seeds:
        res = out / f"seed{seed}"
        t0 = time.time()
        subprocess.run([a.wingman, "run", str(copy), "--seed", str(seed), "--out", str(res), "--no-plots", "-q"],
                       check=True)
        wall = time.time() - t0
        variants = [d for d in sorted(res.iterdir()) if (d / "metrics.json").exists()] or [res]
        for d in variants:
            name = "" if d == res else f" {d.name}"
            print(f"{seed}{name} | {summarise(d, duration, wall)}", flush=True)


if __name__ == "__main__":
    main()
