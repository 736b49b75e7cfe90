"""Batch queries from Python, measured: what a Python call costs beyond the C++ it runs, and a
pose batch over a Dask cluster on this machine with 1 and 2 worker processes. A measurement, not a
test (interleaved rounds, medians).

  PYTHONPATH=build/python python3 python/bench_batch.py [--meshes data/meshes] [--poses 10000]
      [--rounds 5] [--dask-poses 400000] [--cpp build/bench_batch] [--out FILE.md]

- One call on two tetrahedra: Python's caliber.query against the C++ caliber::query (bench_batch
  --tiny-only, run between the Python rounds).
- A pose batch of the turbine (scaled 0.3) through the bunny along bench_batch's path: per pose,
  Python's query loop and query_many (1 and 2 threads) against the C++ batch inside the same call
  (Batch.batch_ms), free and colliding poses apart.
- caliber.distributed over a LocalCluster of 1 and of 2 worker processes (one thread each): the
  same distance pose batch, the same Batch as query_many.
"""
import argparse
import os
import re
import statistics
import subprocess
import time

import numpy as np

import caliber
import caliber.distributed


def path(a, b, n):
    """bench_batch's path: b's centre from one side of a to the other, turning 1.5 times about an axis."""
    def box(m):
        v = m.vertices
        lo, hi = v.min(axis=0), v.max(axis=0)
        return 0.5 * (lo + hi), float(np.linalg.norm(hi - lo))
    ca, da = box(a)
    cb, _ = box(b)
    start, end = ca + np.array([-0.45, -0.1, 0.05]) * da, ca + np.array([0.45, 0.1, -0.05]) * da
    axis = np.array([0.3, 1.0, 0.2]) / np.linalg.norm([0.3, 1.0, 0.2])
    out = np.zeros((n, 7))
    for i in range(n):
        s = i / (n - 1) if n > 1 else 0.0
        half = 1.5 * np.pi * s
        q = np.concatenate([[np.cos(half)], np.sin(half) * axis])
        w, x, y, z = q
        r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                      [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                      [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        out[i, :3] = start + s * (end - start) - r @ cb
        out[i, 3:] = q
    return out


def per_call(f, calls):
    start = time.perf_counter()
    for _ in range(calls):
        f()
    return (time.perf_counter() - start) / calls * 1e6


def tiny(args, lines):
    t = caliber.Model(caliber.Mesh(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float),
                                   np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])), oriented_boxes=True)
    ident, apart = caliber.Pose(), caliber.Pose([1.5, 0.2, 0.1], [1, 0.1, 0.2, 0.3])
    py_d, py_i, cpp_d, cpp_i = [], [], [], []
    for _ in range(args.rounds):
        out = subprocess.run([args.cpp, "--tiny-only", "--repeat", "1"], capture_output=True, text=True, check=True).stdout
        cpp_d.append(float(re.search(r"caliber::query ([0-9.]+) us, fcl", out).group(1)))
        cpp_i.append(float(re.search(r"\(apart\): caliber::query ([0-9.]+) us", out).group(1)))
        py_d.append(per_call(lambda: caliber.query(t, ident, t, apart, kind="distance"), 100000))
        py_i.append(per_call(lambda: caliber.query(t, ident, t, apart), 100000))
    for name, p, c in [("interference (apart, no pair)", py_i, cpp_i), ("distance", py_d, cpp_d)]:
        p, c = statistics.median(p), statistics.median(c)
        lines.append(f"| {name} | {c:.3f} | {p:.3f} | {p - c:.3f} |")


def models(args):
    """The bunny and CGAL's turbine scaled 0.3 (the link swept through it)."""
    bunny = caliber.Model.load(os.path.join(args.meshes, "bunny00.off"), oriented_boxes=True)
    mesh = caliber.Mesh.load(os.path.join(args.meshes, "turbine.off"))
    return bunny, caliber.Model(caliber.Mesh(mesh.vertices * 0.3, mesh.faces), oriented_boxes=True)


def path_batch(args, lines):
    bunny, link = models(args)
    poses = path(bunny.mesh, link.mesh, args.poses)
    ident = caliber.Pose()
    hits = caliber.query_many(bunny, ident, link, poses, max_pairs=1).hit
    kinds = [("first hit", dict(max_pairs=1)), ("interference (every pair)", {}), ("distance", dict(kind="distance"))]
    for name, kw in kinds:
        for subset, rows in [("free", poses[~hits]), ("colliding", poses[hits])]:
            n = len(rows)
            times = {k: [] for k in ("loop", "b1", "b1_cpp", "b2", "b2_cpp")}
            pose_objects = [caliber.Pose(r[:3], r[3:]) for r in rows]
            for _ in range(args.rounds):
                start = time.perf_counter()
                for p in pose_objects:
                    caliber.query(bunny, ident, link, p, **kw)
                times["loop"].append((time.perf_counter() - start) / n * 1e6)
                for threads in (1, 2):
                    start = time.perf_counter()
                    b = caliber.query_many(bunny, ident, link, rows, threads=threads, **kw)
                    times[f"b{threads}"].append((time.perf_counter() - start) / n * 1e6)
                    times[f"b{threads}_cpp"].append(b.batch_ms * 1e3 / n)
            m = {k: statistics.median(v) for k, v in times.items()}
            lines.append(f"| {name} | {subset} | {n} | {m['loop']:.2f} | {m['b1']:.2f} | {m['b1_cpp']:.2f} | "
                         f"{m['b1'] / m['b1_cpp']:.3f} | {m['b2']:.2f} | {m['b2_cpp']:.2f} | {m['b2'] / m['b2_cpp']:.3f} | "
                         f"{m['b1'] / m['b2']:.2f} |")
            print(lines[-1], flush=True)


def dask(args, lines):
    import distributed
    bunny, link = models(args)
    poses = path(bunny.mesh, link.mesh, args.dask_poses)
    want = None
    seconds = {1: [], 2: []}
    clusters = {w: distributed.LocalCluster(n_workers=w, threads_per_worker=1, processes=True, dashboard_address=None)
                for w in (1, 2)}
    clients = {w: distributed.Client(c) for w, c in clusters.items()}
    try:
        for r in range(args.rounds):
            for w in ((1, 2) if r % 2 == 0 else (2, 1)):
                start = time.perf_counter()
                got = caliber.distributed.query_many(clients[w], bunny, caliber.Pose(), link, poses, kind="distance",
                                                     chunk=args.dask_chunk)
                seconds[w].append(time.perf_counter() - start)
                if want is None:
                    want = caliber.query_many(bunny, caliber.Pose(), link, poses, kind="distance", threads=2)
                assert got.pairs.tobytes() == want.pairs.tobytes() and got.distances.tobytes() == want.distances.tobytes()
                print(f"dask {w} worker(s): {seconds[w][-1]:.2f} s", flush=True)
    finally:
        for c in clients.values():
            c.close()
        for c in clusters.values():
            c.close()
    s1, s2 = statistics.median(seconds[1]), statistics.median(seconds[2])
    lines.append(f"| {len(poses)} | {args.dask_chunk} | {s1:.2f} | {s2:.2f} | {s1 / s2:.2f} |")


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--meshes", default="data/meshes")
    p.add_argument("--poses", type=int, default=10000)
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--dask-poses", type=int, default=150000)
    p.add_argument("--dask-chunk", type=int, default=2500)
    p.add_argument("--cpp", default="build/bench_batch")
    p.add_argument("--out")
    p.add_argument("--skip", nargs="*", default=[], choices=["tiny", "path", "dask"])
    args = p.parse_args()
    t_lines = ["| call | C++ us | Python us | Python - C++ us |", "|---|---|---|---|"]
    s_lines = ["| query | poses | count | Python loop | query_many 1t | C++ batch 1t | ratio | query_many 2t | "
               "C++ batch 2t | ratio | 2t speed-up |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    d_lines = ["| poses | chunk | 1 worker s | 2 workers s | speed-up |", "|---|---|---|---|---|"]
    if "tiny" not in args.skip:
        tiny(args, t_lines)
        print("\n".join(t_lines), flush=True)
    if "path" not in args.skip:
        path_batch(args, s_lines)
    if "dask" not in args.skip:
        dask(args, d_lines)
        print("\n".join(d_lines), flush=True)
    if args.out:
        with open(args.out, "w") as f:
            f.write("## One call on two tetrahedra (microseconds)\n\n" + "\n".join(t_lines) + "\n\n")
            f.write("## The path batch from Python (microseconds per pose; ratio: Python's call over the C++ batch inside "
                    "it)\n\n" + "\n".join(s_lines) + "\n\n")
            f.write("## caliber.distributed, distance, LocalCluster of 1 and 2 worker processes\n\n" +
                    "\n".join(d_lines) + "\n")


if __name__ == "__main__":
    main()
