#!/usr/bin/env python3
"""Sequential over stealing on 2 threads, each binary's own: for each binary and round, a run of
`sequential` on 1 thread then one of `stealing` on 2, back to back, each run's median step time from
`caliber run --json`; prints per binary the medians of the runs, their ratio, and the median of the
rounds' ratios.

    python3 step_ratios.py CALIBER[,CALIBER...] SCENE STEPS ROUNDS   (from the repository root)
"""
import statistics
import sys

from compare_steps import step_ms  # (this folder's: each run's median step)


def main():
    binaries, scene, steps, rounds = sys.argv[1].split(","), sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
    configs = [("sequential", 1), ("stealing", 2)]
    runs = {(b, c): [] for b in binaries for c in configs}
    for _ in range(rounds):
        for b in binaries:
            for c in configs:
                runs[(b, c)].append(step_ms(b, scene, steps, *c))
    for b in binaries:
        seq, two = runs[(b, configs[0])], runs[(b, configs[1])]
        s, t = statistics.median(seq), statistics.median(two)
        per_round = statistics.median(x / y for x, y in zip(seq, two))
        print(f"| {scene} | {b} | {s:.4f} | {t:.4f} | {s / t:.3f} | {per_round:.3f} |", flush=True)


if __name__ == "__main__":
    main()
