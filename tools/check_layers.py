#!/usr/bin/env python3
"""Checks that every #include "<module>/..." of the sources follows the module graph of
docs/design.md (modules and the dependency rule): a module includes itself and what its arrows
reach, nothing above it and no sibling. Exit 1 naming each include that breaks the rule.
  tools/check_layers.py [REPO]"""
import pathlib
import re
import sys

# What each module may include directly; a module may also include what those reach.
GRAPH = {
    "geometry": [],
    "io": [],
    "sim": ["geometry"],
    "slam": ["geometry"],
    "control": ["geometry"],
    "vision": ["geometry"],
    "render": ["sim", "geometry"],
    "datasets": ["sim", "geometry"],
    "eval": ["geometry", "io"],
    "frontend_bench": ["eval", "datasets", "vision", "io"],
    "app/config": ["sim", "slam", "control", "vision", "eval", "io"],
    "app/frontend": ["app/config", "render", "vision"],
    "app/pipeline": ["app/frontend", "datasets"],
    "app/batch": ["app/pipeline"],
    "app/cli": ["app/batch", "frontend_bench"],
}
# render reads sim's world and camera descriptions, its asset lookup and its random numbers, nothing
# else of sim.
RENDER_FROM_SIM = {"sim/world.hpp", "sim/camera_sensor.hpp", "sim/assets.hpp", "sim/rng.hpp"}


def reach(module):
    seen, todo = set(), [module]
    while todo:
        m = todo.pop()
        if m in seen:
            continue
        seen.add(m)
        todo.extend(GRAPH[m])
    return seen


def module_of(rel):
    parts = rel.split("/")
    if parts[0] == "app" and len(parts) > 2:
        return "app/" + parts[1]
    if parts[0] == "datasets":
        return "datasets"
    return parts[0] if parts[0] in GRAPH else None


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)
    include = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
    bad = []
    for path in sorted(root.glob("**/*.[ch]pp")):
        rel = path.relative_to(root).as_posix()
        if rel.startswith(("build", "tests/", "bench/", ".")):
            continue
        m = module_of(rel)
        if m is None:
            continue
        allowed = reach(m)
        for inc in include.findall(path.read_text(errors="replace")):
            target = module_of(inc) if "/" in inc else None
            if target is None:
                continue
            if target not in allowed:
                bad.append(f"{rel}: includes {inc} ({m} may not include {target})")
            elif m == "render" and target == "sim" and inc not in RENDER_FROM_SIM:
                bad.append(f"{rel}: includes {inc} (render reads only sim's world and camera descriptions, assets and random numbers)")
    for line in bad:
        print(line)
    print(f"check_layers: {len(bad)} include(s) against the module graph")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
