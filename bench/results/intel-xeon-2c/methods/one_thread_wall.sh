#!/bin/bash
# The methods on one thread, wall time: for 3 rounds, each scene and method, the old and the new
# caliber binary alternating; prints "round scene method old|new narrow_ms" (the sum of narrow_ms
# over 40 steps of `caliber run --threads 1 --json`). Run from the repository's root:
#   bash bench/results/intel-xeon-2c/methods/one_thread_wall.sh OLD_CALIBER NEW_CALIBER
set -euo pipefail
old="$1" new="$2" json="$(mktemp)"
trap 'rm -f "$json"' EXIT
for round in 1 2 3; do
  for sc in two_small funnel front_car; do
    for m in sequential stealing hybrid; do
      for b in old new; do
        bin=$([ "$b" = old ] && echo "$old" || echo "$new")
        "$bin" run "scenes/$sc.json" --method "$m" --threads 1 --steps 40 --json "$json" > /dev/null 2>&1
        python3 -c "import json; d = json.load(open('$json')); print('$round $sc $m $b', round(sum(s['narrow_ms'] for s in d['steps']), 3))"
      done
    done
  done
done
