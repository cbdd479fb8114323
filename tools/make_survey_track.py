#!/usr/bin/env python3
"""Writes scenes/trajectories/survey_track.tum: a ground vehicle's lawnmower survey (80 m legs
20 m apart joined by half circles, 3 m/s, a 1 % climb along x) sampled at 1 Hz in TUM format
(timestamp tx ty tz qx qy qz qw, yaw along the direction of travel), as a GPS/INS log would give it.
  tools/make_survey_track.py [OUT]"""
import math
import sys

SPEED, LEG, SPACING, LEGS, T0 = 3.0, 80.0, 20.0, 4, 1700000000.0


def pose(s):
    """Position and yaw at arc length s along the survey."""
    r = SPACING / 2
    turn = math.pi * r
    period = LEG + turn
    k = min(int(s // period), LEGS - 1)
    u = s - k * period
    y0 = k * SPACING
    right = k % 2 == 0  # even legs run along +x
    if u <= LEG or k == LEGS - 1:
        u = min(u, LEG)
        x = u if right else LEG - u
        return x, y0, 0.0 if right else math.pi
    a = (u - LEG) / r  # angle turned along the half circle
    cx = LEG if right else 0.0
    if right:
        return cx + r * math.sin(a), y0 + r - r * math.cos(a), a
    return cx - r * math.sin(a), y0 + r - r * math.cos(a), math.pi - a


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "scenes/trajectories/survey_track.tum"
    total = LEGS * LEG + (LEGS - 1) * math.pi * SPACING / 2
    lines = ["# timestamp tx ty tz qx qy qz qw"]
    for i in range(int(total / SPEED) + 1):
        x, y, yaw = pose(i * SPEED)
        z = 0.01 * x
        lines.append(f"{T0 + i:.3f} {x:.4f} {y:.4f} {z:.4f} 0 0 {math.sin(yaw / 2):.9f} {math.cos(yaw / 2):.9f}")
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
