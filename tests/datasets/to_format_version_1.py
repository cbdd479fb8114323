#!/usr/bin/env python3
"""Rewrites a dataset of format version 2 (EuRoC/ASL, <agent>/mav0/...) in place into the layout of
format version 1 (<agent>/<sensor>/..., groundtruth/data.csv with 11 columns, groundtruth/cam0.csv
with q_CW, sensor.yaml with R_CW, offset and five distortion coefficients), so that tests can check
that the reader still reads version 1 and gives the same results.

Usage: to_format_version_1.py DATASET_DIR
"""
import csv
import os
import shutil
import sys

import yaml


def rows(path):
    with open(path, newline="") as f:
        return [r for r in csv.reader(f) if r and not r[0].startswith("#")]


def write(path, header, data):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(header + "\n")
        for r in data:
            f.write(",".join(r) + "\n")


def camera_yaml(path, channels):
    y = yaml.safe_load(open(path))
    d = y.pop("T_BS")["data"]
    r_bs = [d[0:3], d[4:7], d[8:11]]
    y["R_CW"] = [r_bs[j][i] for i in range(3) for j in range(3)]  # R_CW = R_BS^T
    y["offset"] = [d[3], d[7], d[11]]
    k = list(y["distortion_coefficients"]) + [0.0] * (5 - len(y["distortion_coefficients"]))
    y["distortion_coefficients"] = k
    y.pop("encoding")
    if channels:
        y["channels"] = channels
    yaml.safe_dump(y, open(path, "w"))


def convert_agent(root, name):
    mav0 = os.path.join(root, name, "mav0")
    agent = os.path.join(root, name)
    gt = rows(os.path.join(mav0, "state_groundtruth_estimate0", "data.csv"))
    write(os.path.join(agent, "groundtruth", "data.csv"), "#t,p,q,v", [r[:11] for r in gt])
    shutil.rmtree(os.path.join(mav0, "state_groundtruth_estimate0"))
    poses = os.path.join(mav0, "cam0_pose0")
    if os.path.isdir(poses):
        cam = [r[:5] + [str(-float(x)) for x in r[5:8]] for r in rows(os.path.join(poses, "data.csv"))]
        write(os.path.join(agent, "groundtruth", "cam0.csv"), "#t,c,q_CW", cam)
        shutil.rmtree(poses)
    shutil.rmtree(os.path.join(mav0, "imu0"), ignore_errors=True)
    for sensor in os.listdir(mav0):
        shutil.move(os.path.join(mav0, sensor), os.path.join(agent, sensor))
    os.rmdir(mav0)
    if os.path.isdir(os.path.join(agent, "cam0")):
        enc = yaml.safe_load(open(os.path.join(agent, "cam0", "sensor.yaml")))["encoding"]
        camera_yaml(os.path.join(agent, "cam0", "sensor.yaml"), 1 if enc == "mono8" else 3)
        camera_yaml(os.path.join(agent, "depth0", "sensor.yaml"), None)


def main():
    root = sys.argv[1]
    info = yaml.safe_load(open(os.path.join(root, "dataset.yaml")))
    for name in info["agents"]:
        convert_agent(root, name)
    info["format_version"] = 1
    yaml.safe_dump(info, open(os.path.join(root, "dataset.yaml"), "w"))
    sums = rows(os.path.join(root, "checksums.csv"))
    write(os.path.join(root, "checksums.csv"), "#file,bytes,crc32",
          [[r[0].replace("/mav0/", "/")] + r[1:] for r in sums])


if __name__ == "__main__":
    main()
