#!/usr/bin/env python3
"""Writes the paper's four benchmark scenes (scenes/*.json) and the procedural meshes they use
(scenes/meshes/*.off). The real meshes come from CGAL's collection (scripts/fetch_meshes.sh puts
them in data/meshes/, which git ignores). Re-run after changing a parameter here:

    python3 scenes/generate.py

With --grid N [N ...] it writes instead the scenes of many parts (data/scenes/grid_N.json, which
git ignores: 100,000 parts make 40 MB of JSON): N copies of CGAL's `eight` refined twice (10,144
triangles each) on a jittered cubic grid, neighbours touching, each drifting and turning, contact
query, 20 steps. `bench/grid_growth.py` measures them (`caliber run` and `caliber-bench` take them
like any scene).
"""
import argparse
import json
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = "../data/meshes/"
STEPS = 150
DT = 0.01


def quat(axis, degrees):
    """Unit quaternion [w, x, y, z] for a rotation of `degrees` about `axis`."""
    n = math.sqrt(sum(a * a for a in axis))
    h = math.radians(degrees) / 2
    s = math.sin(h) / n
    return [math.cos(h), axis[0] * s, axis[1] * s, axis[2] * s]


def qmul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return [w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2]


def rnd(v):
    return [round(x, 9) for x in v]


def write_off(name, vertices, triangles):
    path = os.path.join(HERE, "meshes", name)
    with open(path, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(vertices), len(triangles)))
        for v in vertices:
            f.write("%.9g %.9g %.9g\n" % tuple(v))
        for t in triangles:
            f.write("3 %d %d %d\n" % tuple(t))


def revolution(profile, segments, inward):
    """Surface of revolution about z of a polyline [(r, z), ...]; normals face the axis if inward."""
    vertices, triangles = [], []
    for r, z in profile:
        for j in range(segments):
            a = 2 * math.pi * j / segments
            vertices.append((r * math.cos(a), r * math.sin(a), z))
    for i in range(len(profile) - 1):
        for j in range(segments):
            jn = (j + 1) % segments
            v00, v01 = i * segments + j, i * segments + jn
            v10, v11 = (i + 1) * segments + j, (i + 1) * segments + jn
            if inward:
                triangles += [(v00, v10, v11), (v00, v11, v01)]
            else:
                triangles += [(v00, v11, v10), (v00, v01, v11)]
    return vertices, triangles


def scene(name, objects, kind="contact", tolerance=0.0, angle=30.0, **extra):
    s = {"name": name, "steps": STEPS, "dt": DT,
         "query": {"kind": kind, "tolerance": tolerance, "angle": angle}, "objects": objects}
    s.update(extra)
    with open(os.path.join(HERE, name + ".json"), "w") as f:
        json.dump(s, f, indent=1)
        f.write("\n")


# --- two_small: one pair, about 6k triangles: a knob sliding across another knob's face.
def two_small():
    scene("two_small", [
        {"name": "knob_a", "mesh": DATA + "dragknob.off", "refine": 2},
        {"name": "knob_b", "mesh": DATA + "dragknob.off", "refine": 1,
         "position": [0.40, -0.15, 0.0], "orientation": quat([0, 0, 1], 180),
         "motion": {"type": "velocity", "linear": [0.0, 0.2, 0.0]}},
    ], tolerance=0.01, angle=30)


# --- two_large: one pair, about 400k triangles: the same two knobs, refined, face to face with a
# gap below the tolerance, sliding.
def two_large():
    scene("two_large", [
        {"name": "knob_a", "mesh": DATA + "dragknob.off", "refine": 5},
        {"name": "knob_b", "mesh": DATA + "dragknob.off", "refine": 4,
         "position": [GAP_LARGE, -0.15, 0.0], "orientation": quat([0, 0, 1], 180),
         "motion": {"type": "velocity", "linear": [0.0, 0.2, 0.0]}},
    ], tolerance=0.01, angle=30)


GAP_LARGE = 0.43

def mat_to_quat(m):
    """Unit quaternion [w, x, y, z] of a rotation matrix given as columns (X, Y, Z)."""
    (xx, yx, zx), (xy, yy, zy), (xz, yz, zz) = m[0], m[1], m[2]  # m[c] is column c
    # rows: r0 = (xx, xy, xz) ...
    r = [[m[0][0], m[1][0], m[2][0]], [m[0][1], m[1][1], m[2][1]], [m[0][2], m[1][2], m[2][2]]]
    t = r[0][0] + r[1][1] + r[2][2]
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        return [0.25 * s, (r[2][1] - r[1][2]) / s, (r[0][2] - r[2][0]) / s, (r[1][0] - r[0][1]) / s]
    if r[0][0] > r[1][1] and r[0][0] > r[2][2]:
        s = math.sqrt(1.0 + r[0][0] - r[1][1] - r[2][2]) * 2
        return [(r[2][1] - r[1][2]) / s, 0.25 * s, (r[0][1] + r[1][0]) / s, (r[0][2] + r[2][0]) / s]
    if r[1][1] > r[2][2]:
        s = math.sqrt(1.0 + r[1][1] - r[0][0] - r[2][2]) * 2
        return [(r[0][2] - r[2][0]) / s, (r[0][1] + r[1][0]) / s, 0.25 * s, (r[1][2] + r[2][1]) / s]
    s = math.sqrt(1.0 + r[2][2] - r[0][0] - r[1][1]) * 2
    return [(r[1][0] - r[0][1]) / s, (r[0][2] + r[2][0]) / s, (r[1][2] + r[2][1]) / s, 0.25 * s]


# --- funnel: 17 objects, 16 equal pairs: sixteen "eight" parts slide down the inside of a funnel
# (a surface of revolution, generated here) and come to rest, in contact all along.
FUNNEL_R0, FUNNEL_SLOPE, FUNNEL_H = 0.35, 0.78, 1.6


def funnel():
    profile = [(FUNNEL_R0 + FUNNEL_SLOPE * z, z) for z in [FUNNEL_H * i / 24 for i in range(25)]]
    v, t = revolution(profile, 64, inward=True)
    write_off("funnel.off", v, t)
    norm = math.sqrt(1 + FUNNEL_SLOPE ** 2)
    half_thickness = 0.104 * 0.5  # eight.off is 0.208 thick (y); scaled by 0.5
    press = 0.002                  # the parts lean on the wall: slightly inside it
    objects = [{"name": "funnel", "mesh": "meshes/funnel.off"}]
    for k in range(16):
        phi = 2 * math.pi * k / 16
        er = (math.cos(phi), math.sin(phi), 0.0)
        ephi = (-math.sin(phi), math.cos(phi), 0.0)
        ez = (0.0, 0.0, 1.0)
        n = [(-er[i] + FUNNEL_SLOPE * ez[i]) / norm for i in range(3)]  # wall normal, into the funnel
        g = [(FUNNEL_SLOPE * er[i] + ez[i]) / norm for i in range(3)]   # up along the wall
        q = mat_to_quat([ephi, n, g])

        def at(z):
            r = FUNNEL_R0 + FUNNEL_SLOPE * z
            wall = [r * er[0], r * er[1], z]
            return rnd([wall[i] + n[i] * (half_thickness - press) for i in range(3)])

        objects.append({"name": "part%02d" % k, "mesh": DATA + "eight.off", "refine": 1, "scale": 0.5,
                        "motion": {"type": "keyframes", "keys": [
                            {"time": 0.0, "position": at(1.3), "orientation": rnd(q)},
                            {"time": 1.0, "position": at(0.75), "orientation": rnd(q)}]}})
    scene("funnel", objects, tolerance=0.01, angle=30)


# --- front_car: 23 parts of an assembly. Two knob pairs in sliding contact hold most of the work
# (about 60 % and 30 % of the node tests, the paper's imbalance); nineteen rods form a slowly
# turning cage around them, close enough that almost every pair's bounds overlap (over 200
# pairs) but light to test.
def rod_mesh():
    profile = [(ROD_RADIUS, -ROD_HALF + 2 * ROD_HALF * i / ROD_RINGS) for i in range(ROD_RINGS + 1)]
    v, t = revolution(profile, ROD_SEGMENTS, inward=False)
    write_off("rod.off", v, t)


def front_car():
    rod_mesh()
    objects = [
        {"name": "housing", "mesh": DATA + "dragknob.off", "refine": HEAVY1[0]},
        {"name": "slider", "mesh": DATA + "dragknob.off", "refine": HEAVY1[1],
         "position": [HEAVY1[2], -0.15, 0.0], "orientation": quat([0, 0, 1], 180),
         "motion": {"type": "velocity", "linear": [0.0, 0.2, 0.0]}},
        {"name": "bracket", "mesh": DATA + "dragknob.off", "refine": HEAVY2[0], "position": [0.0, 0.0, 1.1]},
        {"name": "clip", "mesh": DATA + "dragknob.off", "refine": HEAVY2[1],
         "position": [HEAVY2[2], 0.15, 1.1], "orientation": quat([0, 0, 1], 180),
         "motion": {"type": "velocity", "linear": [0.0, -0.2, 0.0]}},
    ]
    golden = math.pi * (3 - math.sqrt(5))
    for i in range(19):
        z = 1 - 2 * (i + 0.5) / 19
        rr = math.sqrt(1 - z * z)
        p = [rr * math.cos(golden * i), rr * math.sin(golden * i), z]
        center = [0.2 + CAGE * p[0], CAGE * p[1], 0.55 + CAGE * p[2]]
        # rod axis: a tangent of the cage sphere, turning with i
        a = [-p[1], p[0], 0.0] if abs(p[2]) < 0.9 else [1.0, 0.0, 0.0]
        na = math.sqrt(sum(x * x for x in a))
        a = [x / na for x in a]
        b = [p[1] * a[2] - p[2] * a[1], p[2] * a[0] - p[0] * a[2], p[0] * a[1] - p[1] * a[0]]
        c, s = math.cos(i), math.sin(i)
        axis = [c * a[k] + s * b[k] for k in range(3)]
        # rotate the rod's z axis onto `axis`
        cross = [-axis[1], axis[0], 0.0]
        ang = math.degrees(math.acos(max(-1.0, min(1.0, axis[2]))))
        q = quat(cross, ang) if math.sqrt(cross[0] ** 2 + cross[1] ** 2) > 1e-9 else [1, 0, 0, 0]
        objects.append({"name": "rod%02d" % i, "mesh": "meshes/rod.off", "position": rnd(center),
                        "orientation": rnd(q),
                        "motion": {"type": "velocity", "angular": rnd([0.1 * p[0], 0.1 * p[1], 0.1 * p[2]])}})
    scene("front_car", objects, tolerance=0.01, angle=30)


HEAVY1 = (4, 3, 0.436)
CAGE = 1.3
ROD_HALF = 4.0
ROD_RADIUS = 0.05
ROD_RINGS = 64
ROD_SEGMENTS = 48
HEAVY2 = (3, 3, 0.433)

# --- grid_N: N parts on a jittered cubic grid, each drifting and turning (the many-object scenes).
GRID_SPACING = 0.88  # the part is 0.49 x 0.21 x 1.0, turned at random: neighbours touch
GRID_JITTER = 0.05
GRID_STEPS = 20


def grid(n, out_dir, mesh_path):
    rng = random.Random(n)
    side = math.ceil(n ** (1.0 / 3.0) - 1e-9)
    mesh = os.path.relpath(mesh_path, out_dir)
    objects = []
    for i in range(n):
        cell = (i % side, (i // side) % side, i // (side * side))
        position = [GRID_SPACING * c + rng.uniform(-GRID_JITTER, GRID_JITTER) for c in cell]
        axis = [rng.gauss(0, 1) for _ in range(3)]
        objects.append({"name": "part%d" % i, "mesh": mesh, "refine": 2, "position": rnd(position),
                        "orientation": rnd(quat(axis, rng.uniform(0, 360))),
                        "motion": {"type": "velocity",
                                   "linear": rnd([rng.uniform(-0.2, 0.2) for _ in range(3)]),
                                   "angular": rnd([rng.uniform(-0.5, 0.5) for _ in range(3)])}})
    path = os.path.join(out_dir, "grid_%d.json" % n)
    with open(path, "w") as f:
        json.dump({"name": "grid_%d" % n, "steps": GRID_STEPS, "dt": DT,
                   "query": {"kind": "contact", "tolerance": 0.0, "angle": 30}, "objects": objects}, f)
        f.write("\n")
    return path


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--grid", type=int, nargs="+", metavar="N", help="write grid_N.json for each N instead")
    parser.add_argument("--out-dir", default=os.path.join(HERE, "..", "data", "scenes"), help="where grid scenes go")
    parser.add_argument("--mesh", default=os.path.join(HERE, DATA, "eight.off"),
                        help="the parts' mesh (CGAL's eight.off), named in the scene relative to --out-dir")
    args = parser.parse_args()
    if args.grid:
        if not os.path.isfile(args.mesh):
            parser.error("--mesh: no such mesh file: %s (scripts/fetch_meshes.sh extracts CGAL's)" % args.mesh)
        os.makedirs(args.out_dir, exist_ok=True)
        for n in args.grid:
            if n < 1:
                parser.error("--grid: a scene needs at least one part")
            print(grid(n, os.path.abspath(args.out_dir), os.path.abspath(args.mesh)))
    else:
        two_small()
        two_large()
        funnel()
        front_car()
