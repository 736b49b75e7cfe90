#!/usr/bin/env python3
"""Scenes whose size grows, to time the CLI on them (bench/results/*/bad_inputs): a baked animation
of K keys (one every millisecond, a step every ten), and N parts in rows with 4 `ignore` pairs
each. Both reference a tetrahedron by absolute path.

    python3 bench/hostile_scenes.py OUT_DIR [--keys 30000 120000] [--parts 10000 40000]
    /usr/bin/time -f '%e s' build/caliber run OUT_DIR/keys_120000.json --steps 12000
    /usr/bin/time -f '%e s' build/caliber run OUT_DIR/ignore_40000.json --steps 2
"""
import argparse
import json
import os

TETRA = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "tests", "data", "tetra.off"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out_dir")
    parser.add_argument("--keys", type=int, nargs="+", default=[30000, 120000])
    parser.add_argument("--parts", type=int, nargs="+", default=[10000, 40000])
    args = parser.parse_args()
    os.makedirs(args.out_dir, exist_ok=True)
    for k in args.keys:
        keys = [{"time": i * 0.001, "position": [i * 1e-3, 0, 0]} for i in range(k)]
        scene = {"steps": 5, "dt": 0.01, "objects": [
            {"name": "a", "mesh": TETRA, "motion": {"type": "keyframes", "keys": keys}},
            {"name": "b", "mesh": TETRA, "position": [0, 5, 0]}]}
        with open(os.path.join(args.out_dir, f"keys_{k}.json"), "w") as f:
            json.dump(scene, f)
    for n in args.parts:
        objects = [{"name": f"p{i}", "mesh": TETRA, "position": [i % 200 * 3.0, (i // 200) * 3.0, 0]} for i in range(n)]
        objects[0]["motion"] = {"type": "velocity", "linear": [1, 0, 0]}
        ignore = [[f"p{i}", f"p{(i + k) % n}"] for i in range(n) for k in (1, 2, 3, 4)]
        with open(os.path.join(args.out_dir, f"ignore_{n}.json"), "w") as f:
            json.dump({"steps": 2, "objects": objects, "ignore": ignore}, f)


if __name__ == "__main__":
    main()
