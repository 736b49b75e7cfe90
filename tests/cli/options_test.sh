#!/usr/bin/env bash
# The command line's options checked before any work, whatever the mode: an option the mode does
# not read is refused by name, every value is checked before the scene is read, and a scene file's
# number too small for a double or nesting too deep is refused with its path; a scene's object is
# named in the errors of its scale and position.
set -u
cli="$1"
data="$(cd "$2" && pwd)"
source "$(dirname "$0")/check_lib.sh"
scene="$data/scenes/tetras.json"
h=$(mktemp -d)

# Options --continuous does not read, and the steps' options without their mode.
check continuous-beta 2 "$cli" run "$scene" --continuous --beta nan
contains continuous-beta "--continuous: reports the pairs that touch between steps: it takes none of"
contains continuous-beta "(--beta given)"
check continuous-simulate 2 "$cli" run "$scene" --continuous --simulate-cores 0
contains continuous-simulate "(--simulate-cores given)"
check continuous-max-pairs-zero 2 "$cli" run "$scene" --continuous --max-pairs 0
contains continuous-max-pairs-zero "(--max-pairs given)"
check continuous-runs 0 "$cli" run "$scene" --continuous --steps 3 --sweep-tolerance 0.01 --method stealing --threads 2
contains continuous-runs "summary over 2 step intervals"
check sweep-tolerance-alone 2 "$cli" run "$scene" --sweep-tolerance 0.1
contains sweep-tolerance-alone "--sweep-tolerance: is read only with --continuous"
check bvh-depth-alone 2 "$cli" run "$scene" --bvh-depth -7
contains bvh-depth-alone "--bvh-depth: is read only with --export DIR"
check export-steps-alone 2 "$cli" run "$scene" --export-steps 3
contains export-steps-alone "--export-steps: is read only with --export DIR"
# The methods' own options, with another method (stealing is the default).
check beta-stealing 2 "$cli" run "$scene" --beta 3
contains beta-stealing "--beta: is read only by the calibrated methods: aposteriori, apriori, hybrid (--method stealing)"
check depth-hybrid 2 "$cli" run "$scene" --method hybrid --stealing-depth 3
contains depth-hybrid "--stealing-depth: is read only by --method stealing (--method hybrid)"
check history-apriori 2 "$cli" run "$scene" --method apriori --node-history
contains history-apriori "--node-history: is read only by --method hybrid"
check hybrid-options 0 "$cli" run "$scene" --method hybrid --node-history --beta 3 --epsilon 0.5 --steps 2
check stealing-depth-ok 0 "$cli" run "$scene" --stealing-depth 3 --steps 2

# Values checked before the scene is read (the scene named here does not exist), in the option's
# own name.
for mode in "" --continuous; do
  check "threads-first$mode" 2 "$cli" run "$h/none.json" $mode --threads 99999
  contains "threads-first$mode" "--threads: must be between 0 and 1024"
done
check view-threads-first 2 "$cli" view "$h/none.json" --out "$h/v.html" --threads 99999
contains view-threads-first "--threads: must be between 0 and 1024"
check bad-method 2 "$cli" run "$h/none.json" --method bogus
contains bad-method "--method: unknown method 'bogus'"
check view-bad-method 2 "$cli" view "$h/none.json" --out "$h/v.html" --method bogus
contains view-bad-method "--method: unknown method 'bogus'"
check export-steps-negative 2 "$cli" run "$h/none.json" --export "$h/e" --export-steps 3,-1
contains export-steps-negative "--export-steps: step -1 is negative"
check stealing-depth 2 "$cli" run "$h/none.json" --stealing-depth -3
contains stealing-depth "--stealing-depth: must be >= 0"
check epsilon 2 "$cli" run "$h/none.json" --method apriori --epsilon -1
contains epsilon "--epsilon: must be a finite number >= 0"
check simulate-cores 2 "$cli" run "$h/none.json" --simulate-cores 2,0
contains simulate-cores "--simulate-cores: core counts must be in [1, 4096]"
check view-steps-limit 2 "$cli" view "$h/none.json" --out "$h/v.html" --steps 200000000
contains view-steps-limit "--steps: must be at most 100000000"
[ -e "$h/v.html" ] && { echo "FAIL view-steps-limit: wrote $h/v.html"; failures=$((failures + 1)); }
# A long --export-steps list (as long as one argument may be) with a step twice.
steps=$(seq -s, 0 15999),7
check export-steps-long 2 timeout 20 "$cli" run "$scene" --export "$h/e" --export-steps "$steps"
contains export-steps-long "--export-steps: step 7 is listed twice"
[ -e "$h/e" ] && { echo "FAIL export-steps-long: made $h/e"; failures=$((failures + 1)); }

# Scene numbers below the doubles' range (read as 0 by the parser), and nesting too deep.
printf '{"steps": 2, "dt": 1e-400, "objects": [{"mesh": "%s/tetra.off"}]}' "$data" > "$h/dt.json"
check scene-underflow 2 "$cli" run "$h/dt.json"
contains scene-underflow "dt.json: 'dt': is too small for a double (it would be read as 0): 1e-400"
printf '{"objects": [{"mesh": "%s/tetra.off", "position": [0, -2.5e-999, 0]}]}' "$data" > "$h/pos.json"
check scene-underflow-array 2 "$cli" run "$h/pos.json"
contains scene-underflow-array "'objects[0].position[1]': is too small for a double"
printf '{"steps": 2, "dt": 0e-5, "objects": [{"mesh": "%s/tetra.off"}]}' "$data" > "$h/zero.json"
check scene-zero 2 "$cli" run "$h/zero.json"
contains scene-zero "'dt': must be > 0"
python3 -c "print('{\"a\":' * 100000 + '1' + '}' * 100000)" > "$h/deep.json"
check scene-deep 2 "$cli" run "$h/deep.json"
contains scene-deep "deep.json: nests deeper than 256 levels, at 'a.a.a."
printf '{"dt": [1, 2, 1e400]}' > "$h/over.json"
check scene-overflow 2 "$cli" run "$h/over.json"
contains scene-overflow "over.json: 'dt[2]': not valid JSON:"
printf '{"": 1, "": 2}' > "$h/empty_key.json"
check scene-empty-key 2 "$cli" run "$h/empty_key.json"
contains scene-empty-key "'\"\"': the key is given twice in one object"

# A scene's objects named in errors: a scale that takes a vertex out of range, a still object out
# of range where it stands (it was said to move), a mesh behind a loop of links (it was "no such
# file").
printf '{"steps": 2, "objects": [{"name": "big", "mesh": "%s/tetra.off", "scale": 1e300}]}' "$data" > "$h/big.json"
check scale-huge 2 "$cli" run "$h/big.json"
contains scale-huge "big.json: object 'big' (objects[0].scale): "
contains scale-huge "scaling by 1e+300 puts vertex"
printf '{"steps": 2, "objects": [{"name": "far", "mesh": "%s/tetra.off", "position": [1e16, 0, 0]}]}' "$data" > "$h/far.json"
check still-far 2 "$cli" run "$h/far.json"
contains still-far "object 'far' (objects[0].position) lies beyond +-1e15"
ln -s loop_b.off "$h/loop_a.off"
ln -s loop_a.off "$h/loop_b.off"
printf '{"objects": [{"mesh": "loop_a.off"}]}' > "$h/loop.json"
check scene-link-loop 2 "$cli" run "$h/loop.json"
contains scene-link-loop "'objects[0].mesh': cannot be read ("
check query-link-loop 2 "$cli" query "$h/loop_a.off" "$data/tetra.off"
contains query-link-loop "loop_a.off: cannot be read ("

# An output that is a named pipe with no reader: waited for, and Ctrl-C stops the wait (the open
# blocked where the signal could not stop it); with a reader, the report goes through the pipe.
mkfifo "$h/pipe"
check pipe-no-reader 130 timeout --preserve-status -k 10 -s INT 1 "$cli" run "$scene" --json "$h/pipe" --steps 2
contains pipe-no-reader "no reader opened the pipe (--json) before SIGINT"
cat "$h/pipe" > "$h/piped.json" &
check pipe-reader 0 "$cli" run "$scene" --json "$h/pipe" --steps 2
wait
python3 -c "import json, sys; assert len(json.load(open(sys.argv[1]))['steps']) == 2" "$h/piped.json" && passes=$((passes + 1)) ||
  { echo "FAIL pipe-reader: $(head -c 200 "$h/piped.json")"; failures=$((failures + 1)); }
rm -rf "$h"

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
