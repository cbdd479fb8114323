#!/usr/bin/env python3
"""Renders the image datasets a marker-free lead detector learns from and is scored on: the three
leads (truck, person, quadrotor) with no cue, over each ground image, from several heights and
offsets, under several suns, with and without shadows. Each dataset is a `wingman render` of a
scenario this tool writes (kept beside it as scenario.yaml); its cam0_lead0 labels are the truth.

  tools/lead_data.py --wingman build/app/wingman --out DIR [--per-pair 2] [--duration 30]
                     [--rate 2] [--grounds freetown,naip,park,site] [--leads truck,person,quadrotor]
                     [--seed 1] [--cue none|aruco]

DIR/<ground>_<lead>_<seed>_<i>/ is one dataset. Everything drawn comes from --seed, so the same command
writes the same datasets. An existing DIR is refused (nothing is replaced)."""
import argparse
import os
import random
import shutil
import subprocess
import sys
import tempfile

GROUNDS = {
    "freetown": "{type: image, image: aerial/freetown_drone_nadir.jpg, mode: tiled, tile_size: 60, anisotropy: 1}",
    "naip": "{type: image, image: aerial/naip_m_4709963_se_14_20200831_5m_rgb.png, mode: tiled, tile_size: 100, "
            "anisotropy: 1}",
    "park": "{type: image, image: aerial/brighton_beach_park_mosaic.jpg, mode: tiled, tile_size: 75.5, anisotropy: 1}",
    "site": "{type: image, image: aerial/caliterra_site_mosaic.jpg, mode: tiled, tile_size: 78, anisotropy: 1}",
}

# model, kind, height, up, yaw offset; the lead's height above the ground; the UAVs' heights above
# the lead and the camera (the shipped scenes' for that lead).
LEADS = {
    "truck": dict(model="models/cesium_milk_truck/CesiumMilkTruck.glb", kind="ground", height=2.6, up="y",
                  yaw=0.0, z=0.0, above=(11.0, 20.0), marker=1.8,
                  camera="{fx: 200.1, fy: 200.1, cx: 500, cy: 500, width: 1000, height: 1000}"),
    "person": dict(model="models/human/HUMAN.glb", kind="ground", height=1.8, up="z", yaw=1.5708, z=0.0,
                   above=(6.5, 12.0), marker=0.6, camera="{fx: 420, fy: 420, cx: 319.5, cy: 239.5, width: 640, height: 480}"),
    "quadrotor": dict(model="models/quadrotor/quadrotor.obj", kind="aerial", height=0.28, up="z", yaw=0.0, z=5.0,
                      above=(5.0, 9.0), marker=0.45, camera="{fx: 420, fy: 420, cx: 319.5, cy: 239.5, width: 640, height: 480}"),
}


def scenario(name, ground, lead, rng, duration, rate, cue):
    L = LEADS[lead]
    uavs = []
    for i in (1, 2):
        above = rng.uniform(*L["above"])
        # Offsets that keep the lead in view of the narrower cameras.
        dx, dy = rng.uniform(-0.45, 0.45) * above, rng.uniform(-0.35, 0.35) * above
        z = L["z"] + above
        uavs.append(f"""  - name: uav{i}
    initial_position: [{dx:.2f}, {dy:.2f}, {z:.2f}]
    sees_lead: true
    altimeter: false
    range: false
    camera: {L["camera"]}""")
    sun_time = rng.uniform(9.0, 15.0)  # at longitude 0 and |latitude| <= 50: the sun is up all year
    shadows = "true" if rng.random() < 0.6 else "false"
    objects = rng.choice(["{boulders: 25, trees: 12, buildings: 2, clearance: 8}",
                          "{boulders: 0, trees: 0, buildings: 0, clearance: 8}"])
    scale = rng.uniform(25, 60)
    return f"""# Lead-detector data (tools/lead_data.py): {ground} ground, {lead}, cue {cue}.
name: {name}
duration: {duration}
rate: {rate}
seed: {rng.randrange(1, 10**6)}
measurements: rendered

lead:
  initial_position: [0, 0, {L["z"]}]
  gps: true
  trajectory: {{type: lemniscate, scale: {scale:.1f}, omega: {rng.uniform(0.03, 0.06):.3f}, z_amplitude: 0,
               z_omega: 0.03}}

uavs:
{chr(10).join(uavs)}

world:
  terrain: {{margin: 30, relief: 1.0, relief_scale: 40, resolution: 2}}
  texture: {GROUNDS[ground]}
  objects: {objects}
  lead: {{model: {L["model"]}, kind: {L["kind"]}, height: {L["height"]}, up: {L["up"]}, yaw_offset: {L["yaw"]},
         cue: {cue}{f", marker_size: {L['marker']}" if cue == "aruco" else ""}}}
  light: {{ambient: {rng.uniform(0.3, 0.5):.2f}, diffuse: {rng.uniform(0.5, 0.8):.2f},
          sun: {{enabled: true, latitude: {rng.uniform(-50, 50):.1f}, longitude: 0, day_of_year: {rng.randrange(1, 366)},
                time_utc: {sun_time:.2f}}},
          shadows: {shadows}}}
  image: {{msaa: 1}}
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--wingman", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--grounds", default=",".join(GROUNDS))
    ap.add_argument("--leads", default=",".join(LEADS))
    ap.add_argument("--per-pair", type=int, default=2, help="datasets per ground and lead")
    ap.add_argument("--duration", type=float, default=30)
    ap.add_argument("--rate", type=float, default=2)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--cue", default="none", choices=["none", "aruco"],
                    help="aruco: the same scenes with the marker, the reference detector's data")
    a = ap.parse_args()
    if os.path.exists(a.out):
        sys.exit(f"lead_data: {a.out} exists; give a new directory")
    for g in a.grounds.split(","):
        if g not in GROUNDS:
            sys.exit(f"lead_data: --grounds: unknown ground '{g}' (known: {', '.join(GROUNDS)})")
    for l in a.leads.split(","):
        if l not in LEADS:
            sys.exit(f"lead_data: --leads: unknown lead '{l}' (known: {', '.join(LEADS)})")
    rng = random.Random(a.seed)
    staging = a.out + ".partial"
    os.makedirs(staging)
    try:
        render_all(a, rng, staging)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)  # nothing half-written
        raise
    os.rename(staging, a.out)
    print(f"lead_data: {a.out}")


def render_all(a, rng, staging):
    with tempfile.TemporaryDirectory() as tmp:
        for g in a.grounds.split(","):
            for l in a.leads.split(","):
                for i in range(a.per_pair):
                    name = f"{g}_{l}_{a.seed}_{i}"
                    path = os.path.join(tmp, name + ".yaml")
                    with open(path, "w") as f:
                        f.write(scenario(name, g, l, rng, a.duration, a.rate, a.cue))
                    print(f"[lead_data] {name}", flush=True)
                    subprocess.run([a.wingman, "render", path, "--out", os.path.join(staging, name), "--gray",
                                    "--quiet"], check=True)


if __name__ == "__main__":
    main()
