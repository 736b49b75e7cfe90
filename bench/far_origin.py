#!/usr/bin/env python3
"""A mesh far from its own origin against the same mesh at its origin: the same meshes (CGAL's
bunny, two copies overlapping), once with their vertices moved to UTM-like coordinates and once
about their origin with the same move in their poses. Medians of interleaved rounds.

    python3 bench/far_origin.py [--meshes data/meshes] [--rounds 5]
"""
import argparse
import os
import time

import numpy as np

import caliber

FAR = np.array([512345.25, 4123456.5, 210.75])  # metres, a UTM zone's easting and northing


def timed(a, pa, b, pb, kind):
    start = time.perf_counter()
    r = caliber.query(a, pa, b, pb, kind=kind, tolerance=0.0 if kind != "distance" else None)
    return time.perf_counter() - start, r


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--meshes", default=os.path.join(os.path.dirname(__file__), "..", "data", "meshes"))
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    mesh = caliber.Mesh.load(os.path.join(args.meshes, "bunny00.off"))
    vertices, triangles = np.array(mesh.vertices), np.array(mesh.faces)
    near = caliber.Model(mesh)
    far_a = caliber.Model(caliber.Mesh(vertices + FAR, triangles))
    posed_a = caliber.Pose(list(FAR), [1, 0, 0, 0])
    print(f"{len(triangles):,} triangles a copy; medians of {args.rounds} interleaved rounds (ms)\n")
    print("| query | about the origin, posed far | far in the vertices | ratio | same pairs |")
    print("|---|---|---|---|---|")
    for kind, shift in (("interference", np.array([0.05, 0.02, 0.0])), ("distance", np.array([1.02, 0.0, 0.0]))):
        far_b = caliber.Model(caliber.Mesh(vertices + FAR + shift, triangles))
        posed_b = caliber.Pose(list(FAR + shift), [1, 0, 0, 0])
        at, far = [], []
        for _ in range(args.rounds):
            t0, r0 = timed(near, posed_a, near, posed_b, kind)
            t1, r1 = timed(far_a, caliber.Pose(), far_b, caliber.Pose(), kind)
            at.append(t0)
            far.append(t1)
        same = r0.pairs.tolist() == r1.pairs.tolist()
        m0, m1 = np.median(at) * 1e3, np.median(far) * 1e3
        print(f"| {kind} | {m0:.2f} | {m1:.2f} | {m1 / m0:.2f} | {same} ({len(r0)} / {len(r1)}) |", flush=True)


if __name__ == "__main__":
    main()
