#!/usr/bin/env python3
"""The scenes' step time with two binaries, alternating: for each scene and configuration (method,
threads), ROUNDS runs of each binary in turn, each run's median step time from `caliber run --json`;
prints the medians of the runs and their ratio (new / old), and each binary's sequential step over
its stealing step on two threads.

    python3 compare_steps.py OLD_CALIBER NEW_CALIBER [ROUNDS]   (from the repository root)
"""
import json
import statistics
import subprocess
import sys
import tempfile

SCENES = {"two_small": 150, "funnel": 40, "front_car": 30, "two_large": 12}
CONFIGS = [("sequential", 1), ("stealing", 2), ("hybrid", 2)]


def step_ms(binary, scene, steps, method, threads):
    with tempfile.NamedTemporaryFile(suffix=".json") as f:
        subprocess.run([binary, "run", f"scenes/{scene}.json", "--method", method, "--threads", str(threads),
                        "--steps", str(steps), "--json", f.name], check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
        return statistics.median(s["step_ms"] for s in json.load(open(f.name))["steps"])


def main():
    old, new = sys.argv[1], sys.argv[2]
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 5
    print("| scene | method | threads | old (ms) | new (ms) | new / old |")
    print("|---|---|---|---|---|---|")
    medians = {}
    for scene, steps in SCENES.items():
        for method, threads in CONFIGS:
            runs = {old: [], new: []}
            for _ in range(rounds):
                for binary in (old, new):
                    runs[binary].append(step_ms(binary, scene, steps, method, threads))
            o, n = statistics.median(runs[old]), statistics.median(runs[new])
            medians[(scene, method, old)], medians[(scene, method, new)] = o, n
            print(f"| {scene} | {method} | {threads} | {o:.4f} | {n:.4f} | {n / o:.3f} |", flush=True)
    print()
    print("| scene | old: sequential / stealing on 2 threads | new: sequential / stealing on 2 threads |")
    print("|---|---|---|")
    for scene in SCENES:
        ratios = [medians[(scene, "sequential", b)] / medians[(scene, "stealing", b)] for b in (old, new)]
        print(f"| {scene} | {ratios[0]:.3f} | {ratios[1]:.3f} |")


if __name__ == "__main__":
    main()
