#!/usr/bin/env python3
"""The growth table of the many-part scenes: for N parts (scenes/generate.py --grid N), per step,
the sequential time, the broad phase's share, the pairs, the time per pair, the peak memory of
the process (with --json on), and the step time on 2 threads for exploitation, stealing and hybrid.
Each configuration is one `caliber run` process; rounds are interleaved and the figures are
medians over rounds of each run's median step (the first step, which builds the broad phase's
tree, is left out).

    python3 bench/grid_growth.py [--objects N ...] [--steps S] [--rounds R] [--out FILE.md]
"""
import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CONFIGS = [("sequential", 1), ("exploitation", 2), ("stealing", 2), ("hybrid", 2)]


def cpu():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def run(cli, scene, method, threads, steps, tmp):
    report = os.path.join(tmp, "run.json")
    cmd = ["/usr/bin/time", "-f", "maxrss %M", cli, "run", scene, "--method", method, "--threads", str(threads),
           "--steps", str(steps), "--json", report]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit("grid_growth: %s failed:\n%s" % (" ".join(cmd), done.stderr[-2000:]))
    rss = [int(l.split()[1]) for l in done.stderr.splitlines() if l.startswith("maxrss")][-1]
    with open(report) as f:
        s = json.load(f)["steps"][1:]
    return {"step_ms": statistics.median(x["broad_ms"] + x["narrow_ms"] + x["reduce_ms"] for x in s),
            "broad_ms": statistics.median(x["broad_ms"] for x in s),
            "pairs": statistics.median(len(x["pairs"]) for x in s),
            "rss_mb": rss / 1024.0}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--objects", type=int, nargs="+", default=[1000, 4096, 32768, 100000])
    parser.add_argument("--steps", type=int, default=10)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--cli", default=os.path.join(ROOT, "build", "caliber"))
    parser.add_argument("--out")
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.objects:
            scene = os.path.join(ROOT, "data", "scenes", "grid_%d.json" % n)
            if not os.path.exists(scene):
                subprocess.run([sys.executable, os.path.join(ROOT, "scenes", "generate.py"), "--grid", str(n)], check=True,
                               stdout=subprocess.DEVNULL)
            got = {c: [] for c in CONFIGS}
            for r in range(args.rounds):
                for method, threads in CONFIGS:
                    print("grid_%d: round %d/%d, %s x%d" % (n, r + 1, args.rounds, method, threads), file=sys.stderr)
                    got[(method, threads)].append(run(args.cli, scene, method, threads, args.steps, tmp))
            med = {c: {k: statistics.median(x[k] for x in v) for k in v[0]} for c, v in got.items()}
            seq = med[("sequential", 1)]
            row = "| %d | %.0f | %.2f | %.2f (%.1f %%) | %.2f | %.0f |" % (
                n, seq["pairs"], seq["step_ms"], seq["broad_ms"], 100.0 * seq["broad_ms"] / seq["step_ms"],
                1000.0 * seq["step_ms"] / max(seq["pairs"], 1), max(m["rss_mb"] for m in med.values()))
            for c in CONFIGS[1:]:
                row += " %.2f (%.2fx) |" % (med[c]["step_ms"], seq["step_ms"] / med[c]["step_ms"])
            rows.append(row)
            print(row, flush=True)
    head = ("Machine: %s, %d hardware threads. `python3 bench/grid_growth.py --objects %s --steps %d --rounds %d`: "
            "one `caliber run --json` process per configuration, %d interleaved rounds, medians of each run's median "
            "step (steps 1 to %d). Scenes from `scenes/generate.py --grid N`: N copies of CGAL's eight refined twice "
            "(10,144 triangles) on a jittered grid, neighbours touching, drifting and turning, contact query.\n\n"
            % (cpu(), os.cpu_count(), " ".join(map(str, args.objects)), args.steps, args.rounds, args.rounds,
               args.steps - 1))
    table = ("| objects | pairs / step | sequential ms / step | broad phase ms (share) | us per pair | peak memory MB | "
             "exploitation, 2 threads | stealing, 2 threads | hybrid, 2 threads |\n|---|---|---|---|---|---|---|---|---|\n"
             + "\n".join(rows) + "\n")
    if args.out:
        with open(args.out, "w") as f:
            f.write(head + table)
    print("\n" + head + table)


if __name__ == "__main__":
    main()
