#!/usr/bin/env python3
"""Time per entry of caliber.query_many as the batch grows: one call of N entries of two tetrahedra
(distance on free poses: one contact an entry; interference on colliding poses: several), against a
call of 10,000 entries. A batch's cost should be linear in its entries.

    python3 bench/batch_growth.py [--entries 10000 1000000 10000000] [--repeat 3]
"""
import argparse
import platform
import time

import numpy as np

import caliber

TETRA = (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float),
         np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]))


def per_entry_us(a, b, n, kind, offset, repeat):
    poses = np.zeros((n, 7))  # rows: the translation, then the quaternion w x y z
    poses[:, 0] = offset
    poses[:, 3] = 1.0
    best = []
    for _ in range(repeat):
        start = time.perf_counter()
        batch = caliber.query_many(a, poses, b, caliber.Pose(), kind=kind, threads=1)
        best.append((time.perf_counter() - start) / n * 1e6)
        contacts = len(batch.pairs) if hasattr(batch, "pairs") else None
        del batch
    return sorted(best)[len(best) // 2], contacts


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--entries", type=int, nargs="+", default=[10000, 1000000, 10000000])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    mesh = caliber.Mesh(*TETRA)
    a = caliber.Model(mesh)
    print(f"Machine: {platform.processor() or platform.machine()}; one thread; medians of {args.repeat} calls\n")
    print("| query | entries | contacts | us an entry | over 10,000 entries |")
    print("|---|---|---|---|---|")
    for kind, offset in (("distance", 3.0), ("interference", 0.2)):
        base = None
        for n in args.entries:
            if kind == "interference" and n > 1000000:
                continue
            us, contacts = per_entry_us(a, a, n, kind, offset, args.repeat if n <= 1000000 else 1)
            base = us if base is None else base
            print(f"| {kind} | {n:,} | {contacts if contacts is not None else '-'} | {us:.3f} | {us / base:.2f} |", flush=True)


if __name__ == "__main__":
    main()
