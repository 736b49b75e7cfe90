"""Two Python threads querying at once against one: the GIL is released during a query, so the
queries overlap. Interleaved rounds, medians; prints the speed-up. A measurement, not a test.

    PYTHONPATH=build/python python3 python/bench_threads.py [MESH] [--rounds R] [--queries Q]
"""
import argparse
import statistics
import threading
import time

import caliber


def run(model, pose, queries, threads):
    def work():
        for _ in range(queries // threads):
            caliber.query(model, caliber.Pose(), model, pose, kind="contact", tolerance=0.002)

    start = time.perf_counter()
    ts = [threading.Thread(target=work) for _ in range(threads)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    return time.perf_counter() - start


def main():
    p = argparse.ArgumentParser()
    p.add_argument("mesh", nargs="?", default="data/meshes/bunny00.off")
    p.add_argument("--rounds", type=int, default=7)
    p.add_argument("--queries", type=int, default=8)
    args = p.parse_args()
    model = caliber.Model.load(args.mesh)
    pose = caliber.Pose((0.002, 0.001, 0.0), (0.999, 0.02, 0.03, 0.01))
    one, two = [], []
    for r in range(args.rounds):
        for threads in ((1, 2) if r % 2 == 0 else (2, 1)):
            (one if threads == 1 else two).append(run(model, pose, args.queries, threads))
    m1, m2 = statistics.median(one), statistics.median(two)
    print(f"{args.mesh}: {args.queries} contact queries, {args.rounds} interleaved rounds, medians")
    print(f"  1 thread:  {m1:.3f} s")
    print(f"  2 threads: {m2:.3f} s  speed-up {m1 / m2:.2f}x")


if __name__ == "__main__":
    main()
