#!/usr/bin/env python3
"""Write a copy of a scenario cut to its first DURATION seconds.

    tools/truncate_scenario.py SCENARIO DURATION OUT

Phases and outages (the base's and every variant's) that start at or after DURATION are dropped,
the others end at DURATION at the latest. The copy keeps the scenario's name and every other key.
"""
import sys

import yaml


def clip_windows(items, duration):
    out = []
    for w in items or []:
        if w["from"] >= duration:
            continue
        w = dict(w)
        w["to"] = min(w["to"], duration)
        out.append(w)
    return out


def clip(doc, duration):
    for key in ("phases", "outages"):
        if key in doc:
            doc[key] = clip_windows(doc[key], duration)
            if not doc[key]:
                del doc[key]


def main():
    if len(sys.argv) != 4:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    path, duration, out = sys.argv[1], float(sys.argv[2]), sys.argv[3]
    with open(path) as f:
        doc = yaml.safe_load(f)
    doc["duration"] = duration
    doc.setdefault("name", path.rsplit("/", 1)[-1].rsplit(".", 1)[0])
    clip(doc, duration)
    for v in doc.get("variants", []) or []:
        if "duration" in v:
            v["duration"] = min(v["duration"], duration)
        clip(v, duration)
    with open(out, "w") as f:
        yaml.safe_dump(doc, f, sort_keys=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
