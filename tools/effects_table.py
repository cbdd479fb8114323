#!/usr/bin/env python3
"""Per-variant table of a `wingman montecarlo` run of several imaging variants (docs/studies/
camera-effects.md, "The paper flight per effect"): Table 4 totals, Table 5 final totals, accepted
outliers per channel, NEES, and the frontend's accepted pixel error and lead detection, each the
mean over the seeds with its smallest and largest seed.

usage: tools/effects_table.py RUNS_DIR VARIANT [VARIANT ...]
RUNS_DIR is the runs/ folder of `wingman montecarlo` (seed1/, seed2/, ... each with one
subdirectory per variant).
"""
import json
import statistics
import sys
from pathlib import Path


def row(m):
    t4 = m["table4"]["total"]
    t5 = m["table5"]["total"]["final_mse"]
    out = {f"{a}{k}": t4[ag]["mse"][i] for a, ag in (("h", "lead"), ("1", "uav1"))
           for i, k in enumerate("XYZ")}
    out.update({f"T5{k}": t5[i] for i, k in enumerate("XYZ")})
    for c in m["table3"]:
        out[f"out_{c['channel']}"] = 100 * c["accepted_outlier_fraction"]
    out["nees"] = m["nees"]["mean"]
    fe = m["frontend"]
    out["px_med"] = fe["accepted_error_px"]["median"]
    out["px_p95"] = fe["accepted_error_px"]["p95"]
    out["lead"] = 100 * fe["lead_detection_rate"]
    return out


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    runs = Path(sys.argv[1])
    seeds = sorted((d for d in runs.iterdir() if d.is_dir() and d.name[4:].isdigit() and d.name.startswith("seed")),
                   key=lambda d: int(d.name[4:]))
    cols = ["hX", "hY", "hZ", "1X", "1Y", "1Z", "T5X", "T5Y", "T5Z", "out_uav1", "out_uav2",
            "out_cooperative", "nees", "px_med", "px_p95", "lead"]
    heads = ["Xh", "Yh", "Zh", "X1", "Y1", "Z1", "T5 X", "T5 Y", "T5 Z", "out 1 %", "out 2 %",
             "out coop %", "NEES", "px med", "px p95", "lead %"]
    print(f"means over {len(seeds)} seeds ({', '.join(d.name for d in seeds)}); "
          "below each mean, the smallest and largest seed\n")
    print("| variant | " + " | ".join(heads) + " |")
    print("|---|" + "---:|" * len(heads))
    for v in sys.argv[2:]:
        rows = [row(json.loads((d / v / "metrics.json").read_text())) for d in seeds]
        mean = [statistics.fmean(r[c] for r in rows) for c in cols]
        span = [(min(r[c] for r in rows), max(r[c] for r in rows)) for c in cols]
        fmt = lambda x: f"{x:.3g}"
        print(f"| {v} | " + " | ".join(fmt(x) for x in mean) + " |")
        print("| | " + " | ".join(f"{fmt(a)}–{fmt(b)}" for a, b in span) + " |")


if __name__ == "__main__":
    main()
