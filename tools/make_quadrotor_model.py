#!/usr/bin/env python3
"""Writes the aerial lead's model, assets/models/quadrotor/quadrotor.{obj,mtl}.

A simple X-frame quadrotor, z-up, in metres, front at +X: a central body whose flat top is the
model's highest point (the renderer lays the lead's cue on it, so x_h is the centre of that top),
four arms, four motors and rotor discs below the top, and four landing legs: 0.89 m across x
and y, 1.14 m from rotor tip to rotor tip on a diagonal, 0.28 m tall, 524 triangles. Faces carry
their own normals (flat shading).

    python3 tools/make_quadrotor_model.py [OUT_DIR]
"""
import math
import os
import sys

MATERIALS = {
    "body": (0.25, 0.27, 0.30),
    "arm": (0.10, 0.10, 0.10),
    "front": (0.80, 0.15, 0.10),  # the front arms, so the heading shows from above
    "motor": (0.55, 0.55, 0.58),
    "rotor": (0.80, 0.82, 0.85),
    "leg": (0.15, 0.15, 0.15),
}


class Mesh:
    def __init__(self):
        self.vertices, self.normals, self.groups = [], [], {}

    def face(self, material, pts):
        """A planar convex polygon, counter-clockwise seen from outside."""
        a, b, c = pts[0], pts[1], pts[2]
        u = [b[i] - a[i] for i in range(3)]
        v = [c[i] - a[i] for i in range(3)]
        n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
        length = math.sqrt(sum(x * x for x in n)) or 1.0
        self.normals.append([x / length for x in n])
        ni = len(self.normals)
        idx = []
        for p in pts:
            self.vertices.append(p)
            idx.append(len(self.vertices))
        for k in range(1, len(idx) - 1):  # fan of triangles
            self.groups.setdefault(material, []).append(
                [(idx[0], ni), (idx[k], ni), (idx[k + 1], ni)])

    def box(self, material, centre, size, yaw=0.0):
        cx, cy, cz = centre
        hx, hy, hz = (s / 2 for s in size)
        c, s = math.cos(yaw), math.sin(yaw)

        def p(sx, sy, sz):
            x, y = sx * hx, sy * hy
            return (cx + c * x - s * y, cy + s * x + c * y, cz + sz * hz)

        self.face(material, [p(-1, -1, 1), p(1, -1, 1), p(1, 1, 1), p(-1, 1, 1)])
        self.face(material, [p(-1, 1, -1), p(1, 1, -1), p(1, -1, -1), p(-1, -1, -1)])
        self.face(material, [p(-1, -1, -1), p(1, -1, -1), p(1, -1, 1), p(-1, -1, 1)])
        self.face(material, [p(1, -1, -1), p(1, 1, -1), p(1, 1, 1), p(1, -1, 1)])
        self.face(material, [p(1, 1, -1), p(-1, 1, -1), p(-1, 1, 1), p(1, 1, 1)])
        self.face(material, [p(-1, 1, -1), p(-1, -1, -1), p(-1, -1, 1), p(-1, 1, 1)])

    def cylinder(self, material, centre, radius, z0, z1, segments):
        cx, cy = centre
        ring = [(cx + radius * math.cos(2 * math.pi * k / segments),
                 cy + radius * math.sin(2 * math.pi * k / segments)) for k in range(segments)]
        for k in range(segments):
            (x0, y0), (x1, y1) = ring[k], ring[(k + 1) % segments]
            self.face(material, [(x0, y0, z0), (x1, y1, z0), (x1, y1, z1), (x0, y0, z1)])
            self.face(material, [(cx, cy, z1), (x0, y0, z1), (x1, y1, z1)])
            self.face(material, [(cx, cy, z0), (x1, y1, z0), (x0, y0, z0)])

    def triangles(self):
        return sum(len(f) for f in self.groups.values())


def quadrotor():
    m = Mesh()
    top = 0.28                      # the body's flat top: the highest point
    m.box("body", (0, 0, 0.22), (0.40, 0.30, 0.12))
    arm_z, motor_r = 0.19, 0.42     # arm height, motor distance from the centre
    for k in range(4):
        a = math.pi / 4 + k * math.pi / 2
        mx, my = motor_r * math.cos(a), motor_r * math.sin(a)
        front = math.cos(a) > 0
        m.box("front" if front else "arm", (mx / 2, my / 2, arm_z), (motor_r, 0.035, 0.03), a)
        m.cylinder("motor", (mx, my), 0.03, arm_z - 0.015, arm_z + 0.045, 10)
        m.cylinder("rotor", (mx, my), 0.15, arm_z + 0.045, arm_z + 0.052, 16)
        lx, ly = 0.15 * math.copysign(1, mx), 0.11 * math.copysign(1, my)
        m.box("leg", (lx, ly, 0.08), (0.02, 0.02, 0.16))
    assert top >= arm_z + 0.052
    return m


def write(mesh, out_dir):
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "quadrotor.mtl"), "w") as f:
        f.write("# Materials of quadrotor.obj (tools/make_quadrotor_model.py)\n")
        for name, (r, g, b) in MATERIALS.items():
            f.write(f"newmtl {name}\nKd {r:.3f} {g:.3f} {b:.3f}\nKa 0 0 0\nKs 0 0 0\n\n")
    with open(os.path.join(out_dir, "quadrotor.obj"), "w") as f:
        f.write("# A simple quadrotor, z-up, metres, front at +X (tools/make_quadrotor_model.py)\n")
        f.write("mtllib quadrotor.mtl\n")
        for v in mesh.vertices:
            f.write("v {:.4f} {:.4f} {:.4f}\n".format(*v))
        for n in mesh.normals:
            f.write("vn {:.4f} {:.4f} {:.4f}\n".format(*n))
        for name in MATERIALS:
            if name not in mesh.groups:
                continue
            f.write(f"usemtl {name}\n")
            for tri in mesh.groups[name]:
                f.write("f " + " ".join(f"{v}//{n}" for v, n in tri) + "\n")


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, "assets", "models", "quadrotor")
    mesh = quadrotor()
    write(mesh, out)
    xs = [v[0] for v in mesh.vertices]
    zs = [v[2] for v in mesh.vertices]
    print(f"{out}: {len(mesh.vertices)} vertices, {mesh.triangles()} triangles, "
          f"{max(xs) - min(xs):.2f} m across x, {max(zs) - min(zs):.2f} m tall")


if __name__ == "__main__":
    main()
