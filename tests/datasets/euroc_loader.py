#!/usr/bin/env python3
"""A loader for one EuRoC MAV sequence, written from the dataset's published description
(Burri et al., "The EuRoC micro aerial vehicle datasets", IJRR 2016, and its ASL folder format):
mav0/<sensor>/sensor.yaml with T_BS as {cols, rows, data}; cam0/data.csv "timestamp [ns],filename"
with the images in cam0/data/; imu0/data.csv w_RS_S then a_RS_S; state_groundtruth_estimate0/data.csv
with p_RS_R, q_RS (w first), v_RS_R, b_w_RS_S, b_a_RS_S. It knows nothing of Wingman's writer.

Usage: euroc_loader.py MAV0_DIR [--integrate SECONDS]
Loads and checks the sequence, then integrates the IMU over the ground truth's orientation and
biases and compares the velocity it reaches with the ground truth's; prints one line per check and
exits 1 on the first failure.
"""
import argparse
import csv
import math
import os
import struct
import sys

import yaml

GRAVITY = (0.0, 0.0, -9.81)


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def read_rows(path, columns):
    rows = []
    with open(path, newline="") as f:
        for line_no, row in enumerate(csv.reader(f), 1):
            if not row or row[0].startswith("#"):
                continue
            if len(row) != columns:
                fail("%s:%d: %d columns, EuRoC has %d" % (path, line_no, len(row), columns))
            rows.append(row)
    return rows


def read_sensor_yaml(folder, required):
    path = os.path.join(folder, "sensor.yaml")
    with open(path) as f:
        y = yaml.safe_load(f)
    for key in ["sensor_type", "comment", "T_BS"] + required:
        if key not in y:
            fail("%s: no key %s" % (path, key))
    t = y["T_BS"]
    if t.get("rows") != 4 or t.get("cols") != 4 or len(t.get("data", [])) != 16:
        fail("%s: T_BS is not a 4x4 matrix" % path)
    d = t["data"]
    r = [d[0:3], d[4:7], d[8:11]]
    for i in range(3):
        for j in range(3):
            dot = sum(r[i][k] * r[j][k] for k in range(3))
            if abs(dot - (1.0 if i == j else 0.0)) > 1e-6:
                fail("%s: T_BS's rotation is not orthonormal" % path)
    if d[12:16] != [0, 0, 0, 1]:
        fail("%s: T_BS's last row is not 0 0 0 1" % path)
    return y


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(26)
    if head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        fail("%s: not a PNG" % path)
    width, height = struct.unpack(">II", head[16:24])
    return width, height, head[24], head[25]  # bit depth, colour type (0: grey)


def load_camera(mav0):
    folder = os.path.join(mav0, "cam0")
    y = read_sensor_yaml(folder, ["rate_hz", "resolution", "camera_model", "intrinsics",
                                  "distortion_model", "distortion_coefficients"])
    if y["camera_model"] != "pinhole" or len(y["intrinsics"]) != 4:
        fail("cam0: expected a pinhole camera with fu, fv, cu, cv")
    if y["distortion_model"] == "radial-tangential" and len(y["distortion_coefficients"]) != 4:
        fail("cam0: radial-tangential takes k1, k2, r1, r2")
    frames = [(int(t), name) for t, name in read_rows(os.path.join(folder, "data.csv"), 2)]
    for t, name in frames:
        if name != "%d.png" % t:
            fail("cam0: frame %s is not named after its time stamp" % name)
        w, h, depth, colour = png_size(os.path.join(folder, "data", name))
        if [w, h] != list(y["resolution"]) or depth != 8 or colour != 0:
            fail("cam0/data/%s: %dx%d, %d-bit, colour type %d; expected 8-bit grey %s"
                 % (name, w, h, depth, colour, y["resolution"]))
    steps = [b[0] - a[0] for a, b in zip(frames, frames[1:])]
    if any(abs(s - 1e9 / y["rate_hz"]) > 1e3 for s in steps):
        fail("cam0: frame spacing differs from rate_hz")
    print("cam0: %d frames %sx%s at %s Hz" % (len(frames), y["resolution"][0], y["resolution"][1], y["rate_hz"]))
    return y, frames


def load_imu(mav0):
    folder = os.path.join(mav0, "imu0")
    y = read_sensor_yaml(folder, ["rate_hz", "gyroscope_noise_density", "gyroscope_random_walk",
                                  "accelerometer_noise_density", "accelerometer_random_walk"])
    rows = [[int(r[0])] + [float(x) for x in r[1:]] for r in read_rows(os.path.join(folder, "data.csv"), 7)]
    if any(abs(b[0] - a[0] - 1e9 / y["rate_hz"]) > 1e3 for a, b in zip(rows, rows[1:])):
        fail("imu0: sample spacing differs from rate_hz")
    print("imu0: %d samples at %s Hz" % (len(rows), y["rate_hz"]))
    return y, rows


def load_groundtruth(mav0):
    folder = os.path.join(mav0, "state_groundtruth_estimate0")
    read_sensor_yaml(folder, [])
    rows = [[int(r[0])] + [float(x) for x in r[1:]] for r in read_rows(os.path.join(folder, "data.csv"), 17)]
    for r in rows:
        if abs(math.sqrt(sum(q * q for q in r[4:8])) - 1) > 1e-6:
            fail("state_groundtruth_estimate0: quaternion at %d is not unit" % r[0])
    print("state_groundtruth_estimate0: %d states" % len(rows))
    return rows


def rotate(q, v):  # q = (w, x, y, z), the body-to-world rotation R_RS
    w, x, y, z = q
    r = [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
         [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
         [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]
    return [sum(r[i][k] * v[k] for k in range(3)) for i in range(3)]


def integrate(imu, gt, seconds):
    """Trapezoidal integration of R_RS (a_S - b_a) + g from the first ground-truth velocity."""
    states = {r[0]: r for r in gt}
    t0 = imu[0][0]
    v = list(states[t0][8:11])
    def world_accel(sample):
        s = states[sample[0]]
        a = [sample[4 + i] - s[14 + i] for i in range(3)]
        return [rotate(s[4:8], a)[i] + GRAVITY[i] for i in range(3)]
    last = imu[0]
    for sample in imu[1:]:
        if sample[0] - t0 > seconds * 1e9:
            break
        dt = (sample[0] - last[0]) * 1e-9
        a0, a1 = world_accel(last), world_accel(sample)
        v = [v[i] + 0.5 * (a0[i] + a1[i]) * dt for i in range(3)]
        last = sample
    return (last[0] - t0) * 1e-9, v, states[last[0]][8:11]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mav0")
    ap.add_argument("--integrate", type=float, default=5.0)
    a = ap.parse_args()
    camera, frames = load_camera(a.mav0)
    imu_yaml, imu = load_imu(a.mav0)
    gt = load_groundtruth(a.mav0)
    if not (imu[0][0] <= frames[0][0] and frames[-1][0] <= imu[-1][0]):
        fail("the IMU does not span the camera's frames")
    if {r[0] for r in imu} - {r[0] for r in gt}:
        fail("an IMU sample has no ground-truth state at its time stamp")
    span, v, v_true = integrate(imu, gt, a.integrate)
    # White accelerometer noise integrated over T: sigma_v = noise density * sqrt(T) per axis.
    sigma = imu_yaml["accelerometer_noise_density"] * math.sqrt(span)
    err = [v[i] - v_true[i] for i in range(3)]
    print("velocity after %.3f s: integrated %s, ground truth %s, error %s, sigma %.6f m/s"
          % (span, ["%.5f" % x for x in v], ["%.5f" % x for x in v_true], ["%.5f" % x for x in err], sigma))
    if any(abs(e) > 5 * sigma + 1e-4 for e in err):
        fail("the integrated IMU leaves the ground-truth velocity by more than 5 sigma")
    print("OK")


if __name__ == "__main__":
    main()
