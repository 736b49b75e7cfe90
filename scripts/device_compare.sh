#!/usr/bin/env bash
# The current binaries (.devicepack/bin) against a baseline's (.devicepack/old, packed by
# BASELINE_BUILD=... scripts/device_pack.sh), on the 16-core machine, in alternating runs (new, old,
# old, new for the engine; new, old for the rest), inside one 10-minute command; everything is
# tarred into $OUT/results.tgz after each piece, so a cut run still brings back what finished:
#
#   bash .devicepack/device_compare.sh     # there, with $OUT set
#
# Each piece runs only when its estimate still fits the 565 s deadline.
set -u
start=$(date +%s); deadline=$((start + 565))
here="$(cd "$(dirname "$0")" && pwd)"; cd "$here"
export LD_LIBRARY_PATH="$here/lib"
W=/tmp/res; mkdir -p $W
left() { echo $((deadline - $(date +%s))); }
save() { tar czf "$OUT/results.tgz" -C $W . ; }
log() { echo "[$(( $(date +%s) - start ))s] $*" | tee -a $W/log.txt; }
bin() { if [ "$1" = new ]; then echo "$here/bin/$2"; else echo "$here/old/$2"; fi; }
# The engine bench of a side: its caliber-bench, or an older build's `caliber bench`.
engine_bench() { if [ -x "$(bin "$1" caliber-bench)" ]; then bin "$1" caliber-bench; else echo "$(bin "$1" caliber) bench"; fi; }
# run NAME EST CMD...: runs when EST seconds are left, cut at min(2*EST, left-10)
run() { local name=$1 est=$2; shift 2; local l; l=$(left)
  if [ "$l" -lt "$est" ]; then log "skip $name ($l s left)"; return; fi
  local t=$((2 * est)); [ $t -gt $((l - 10)) ] && t=$((l - 10))
  log "start $name (cut at $t s)"; timeout $t "$@" > $W/$name.out 2>&1; log "end $name rc=$?"; save; }
{ date -u; nproc; lscpu | head -20; free -g; uname -a; } > $W/machine.txt 2>&1
SC="scenes/two_large.json scenes/two_small.json scenes/funnel.json scenes/front_car.json"
E="--methods exploitation stealing hybrid --threads 1 2 4 8 16 --repeat 1 --steps 30 --no-fcl --no-figures --simulate 16 --simulate-steps 2 --budget-s 55"
run eng_new_r1 45 $(engine_bench new) $SC $E --out $W/eng_new_r1
run eng_old_r1 40 $(engine_bench old) $SC $E --no-ceiling --out $W/eng_old_r1
run eng_old_r2 40 $(engine_bench old) $SC $E --no-ceiling --out $W/eng_old_r2
run eng_new_r2 40 $(engine_bench new) $SC $E --no-ceiling --out $W/eng_new_r2
B="--poses 3000 --threads 1 2 4 8 16 --repeat 1"
run batch_new 45 $(bin new bench_batch) $B --out $W/batch_new.md
run batch_old 45 $(bin old bench_batch) $B --out $W/batch_old.md
if (cd .. && python3 scenes/generate.py --grid 32768 --out-dir .devicepack/data/scenes --mesh .devicepack/data/meshes/eight.off) > $W/generate.out 2>&1; then
  G="data/scenes/grid_32768.json --methods stealing hybrid --threads 1 4 16 --repeat 1 --steps 8 --no-fcl --no-figures --simulate 16 --simulate-steps 2 --budget-s 45"
  run grid_new 45 $(engine_bench new) $G --out $W/grid_new
  run grid_old 40 $(engine_bench old) $G --no-ceiling --out $W/grid_old
else log "grid scene generation failed"; fi
S="--motions 40 --seed 1 --rounds 1 --method stealing --threads 1 2 4 8 16"
run sweep_new 30 $(bin new bench_sweep_many) $S --out $W/sweep_new.md
run sweep_old 30 $(bin old bench_sweep_many) $S --out $W/sweep_old.md
run batch_new2 45 $(bin new bench_batch) $B --out $W/batch_new2.md
run batch_old2 45 $(bin old bench_batch) $B --out $W/batch_old2.md
log done; save
