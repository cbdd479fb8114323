#!/usr/bin/env python3
"""How the frontend's pixel error splits along tracks, from a correspondences.csv.

usage: tools/track_error.py CORRESPONDENCES_CSV [--min-obs N] [--until T] [--centre CX CY]

The CSV is what `wingman run --correspondences` writes beside steps.csv (rendered scenarios):
every tracked correspondence offered to the filter, with the landmark's true projection. This
takes the ones the filter accepted and the ground truth labels correct (within 3 px), signed
error e = pixel - true projection, and per camera and over all:

- the RMS of |e|, split exactly into the RMS of each track's mean error vector (a constant per
  camera and landmark) and the RMS of the scatter about it, over tracks of at least --min-obs
  accepted observations;
- the correlation of e with the same track's e L frames later, for L = 1, 5, 10, 20, 50
  (sum of e_k . e_k+L over the pairs, over the root of the two sums of squares): 0 for white
  noise, near the constant's share of the variance for a constant plus white noise;
- the median |e| near the image centre and near the edge (radius from --centre, default the
  paper camera's 500, 500), and the mean signed error per axis (a pattern common to all tracks).
"""
import argparse
import csv
import math
import statistics
import sys
from collections import defaultdict

LAGS = (1, 5, 10, 20, 50)


def load(path, until):
    tracks = defaultdict(dict)  # (cam, landmark) -> {k: (eu, ev, u, v)}
    offered = accepted = accepted_outliers = 0
    with open(path, newline="") as f:
        rows = csv.DictReader(f)
        need = {"k", "t", "cam", "landmark", "u", "v", "true_u", "true_v", "outlier", "accepted"}
        if not rows.fieldnames or not need.issubset(rows.fieldnames):
            sys.exit(f"{path}: not a correspondences.csv (columns {sorted(need)} expected)")
        for r in rows:
            if until is not None and float(r["t"]) > until:
                continue
            offered += 1
            if r["accepted"] != "1":
                continue
            accepted += 1
            if r["outlier"] == "1" or not r["true_u"]:
                accepted_outliers += 1
                continue
            u, v = float(r["u"]), float(r["v"])
            tracks[(int(r["cam"]), int(r["landmark"]))][int(r["k"])] = (
                u - float(r["true_u"]), v - float(r["true_v"]), u, v)
    return tracks, offered, accepted, accepted_outliers


def summarise(tracks, min_obs, centre):
    kept = {key: obs for key, obs in tracks.items() if len(obs) >= min_obs}
    n = sum(len(o) for o in kept.values())
    if n == 0:
        return None
    total = const = scatter = 0.0
    for obs in kept.values():
        mu = sum(e[0] for e in obs.values()) / len(obs), sum(e[1] for e in obs.values()) / len(obs)
        for eu, ev, _, _ in obs.values():
            total += eu * eu + ev * ev
            scatter += (eu - mu[0]) ** 2 + (ev - mu[1]) ** 2
        const += len(obs) * (mu[0] ** 2 + mu[1] ** 2)
    corr = []
    for lag in LAGS:
        num = s0 = s1 = 0.0
        for obs in kept.values():
            for k, (eu, ev, _, _) in obs.items():
                later = obs.get(k + lag)
                if later is None:
                    continue
                num += eu * later[0] + ev * later[1]
                s0 += eu * eu + ev * ev
                s1 += later[0] ** 2 + later[1] ** 2
        corr.append(num / math.sqrt(s0 * s1) if s0 > 0 and s1 > 0 else float("nan"))
    inner, outer, mean_u, mean_v = [], [], 0.0, 0.0
    for obs in kept.values():
        for eu, ev, u, v in obs.values():
            r = math.hypot(u - centre[0], v - centre[1])
            (inner if r < 150 else outer if r > 350 else []).append(math.hypot(eu, ev))
            mean_u += eu
            mean_v += ev
    med = lambda xs: statistics.median(xs) if xs else float("nan")
    return {"tracks": len(kept), "obs": n, "rms": math.sqrt(total / n),
            "track_mean": math.sqrt(const / n), "scatter": math.sqrt(scatter / n), "corr": corr,
            "centre": med(inner), "edge": med(outer), "mean_u": mean_u / n, "mean_v": mean_v / n}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("csv")
    ap.add_argument("--min-obs", type=int, default=10, help="tracks shorter than this are left out")
    ap.add_argument("--until", type=float, help="only the first T seconds")
    ap.add_argument("--centre", type=float, nargs=2, default=(500.0, 500.0), metavar=("CX", "CY"))
    a = ap.parse_args()
    try:
        tracks, offered, accepted, outliers = load(a.csv, a.until)
    except OSError as e:
        sys.exit(f"{a.csv}: {e.strerror}")
    print(f"{a.csv}: {offered} correspondences offered, {accepted} accepted, "
          f"{outliers} of them outliers ({100.0 * outliers / max(accepted, 1):.2f} %)")
    print(f"accepted inliers on tracks of >= {a.min_obs}; px; corr: with the same track L frames later\n")
    print("| camera | tracks | observations | rms | track mean | scatter | "
          + " | ".join(f"corr L={lag}" for lag in LAGS)
          + " | median, r < 150 | median, r > 350 | mean u | mean v |")
    print("|---" * (10 + len(LAGS)) + "|")
    cams = sorted({cam for cam, _ in tracks})
    for label, sel in [(str(c), {k: o for k, o in tracks.items() if k[0] == c}) for c in cams] + [("all", tracks)]:
        s = summarise(sel, a.min_obs, a.centre)
        if s is None:
            print(f"| {label} | 0 | 0 |" + " - |" * (7 + len(LAGS)))
            continue
        print(f"| {label} | {s['tracks']} | {s['obs']} | {s['rms']:.3f} | {s['track_mean']:.3f} | "
              f"{s['scatter']:.3f} | " + " | ".join(f"{c:.2f}" for c in s["corr"])
              + f" | {s['centre']:.3f} | {s['edge']:.3f} | {s['mean_u']:+.3f} | {s['mean_v']:+.3f} |")


if __name__ == "__main__":
    main()
