#!/usr/bin/env bash
# Compares the speed of the working tree with another revision on this machine, in one run:
# builds REV (Release, into build-compare/REV/, from a git worktree beside the repo), then runs
# both binaries in interleaved rounds (old, new, old, new, ...) and prints per-case medians and
# the ratio new / old. Every speed claim between two versions is such a ratio, measured in one run.
#
#   scripts/compare_commits.sh REV [--rounds R] [--steps K] [--scenes two_small,funnel,...]
#                                  [--no-queries] [--new BINARY] [--method M] [--threads T]
#
# Cases: each scene's step (median ms/step of `caliber run --method M --threads T --steps K`,
# sequential on 1 thread unless told; two_large runs K/3 steps), and the interference query of the FCL
# comparison's mesh pairs (`caliber query`'s query_ms; the median of R rounds). The contacts of
# every scene and the pairs of every query are compared too (the `--contacts` files of old and new, byte for byte; where
# one version writes fields the other does not, every field both write, value for value): a speed-up
# that changed a contact is reported as a mismatch and the script exits 1.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
rev="${1:?usage: compare_commits.sh REV [--rounds R] [--steps K] [--scenes a,b] [--no-queries] [--new BINARY]}"
shift
rounds=5
steps=60
scenes="two_large,two_small,funnel,front_car"
queries=1
method=sequential
threads=1
new_bin="$root/build/caliber"
while [ $# -gt 0 ]; do
  case "$1" in
    --rounds|--steps|--scenes|--new|--method|--threads) [ $# -ge 2 ] || { echo "compare_commits: $1 needs a value" >&2; exit 2; } ;;&
    --rounds) rounds="$2"; shift 2 ;;
    --steps) steps="$2"; shift 2 ;;
    --scenes) scenes="$2"; shift 2 ;;
    --no-queries) queries=0; shift ;;
    --new) new_bin="$2"; shift 2 ;;
    --method) method="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    *) echo "compare_commits: unknown option '$1'" >&2; exit 2 ;;
  esac
done
[[ "$rounds" =~ ^[1-9][0-9]*$ ]] || { echo "compare_commits: --rounds must be a whole number >= 1" >&2; exit 2; }
[[ "$threads" =~ ^[1-9][0-9]*$ ]] || { echo "compare_commits: --threads must be a whole number >= 1" >&2; exit 2; }
[[ "$steps" =~ ^[1-9][0-9]*$ ]] || { echo "compare_commits: --steps must be a whole number >= 1" >&2; exit 2; }
sha="$(git -C "$root" rev-parse --verify "$rev^{commit}" 2>/dev/null)" || {
  echo "compare_commits: '$rev' is not a revision of this repository" >&2; exit 2; }
short="${sha:0:10}"
[ -x "$new_bin" ] || { echo "compare_commits: $new_bin is missing: run scripts/build.sh first" >&2; exit 2; }

old_dir="$root/build-compare/$short"
old_bin="$old_dir/build/caliber"
if [ ! -x "$old_bin" ]; then
  echo "compare_commits: building $short into $old_dir" >&2
  rm -rf "$old_dir/src"
  mkdir -p "$old_dir"
  git -C "$root" worktree prune
  git -C "$root" worktree add --detach "$old_dir/src" "$sha" >/dev/null
  cmake -S "$old_dir/src" -B "$old_dir/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
  # Revisions before the embed step made its own folder fail without viewer/node_modules.
  mkdir -p "$old_dir/build/viewer"
  cmake --build "$old_dir/build" -j "${JOBS:-2}" --target caliber_cli >/dev/null
  git -C "$root" worktree remove --force "$old_dir/src"
fi

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
IFS=',' read -r -a scene_list <<< "$scenes"

# Mesh pairs of the FCL comparison (bench/fcl_compare.cpp), placed as it places them: A at the
# identity, B turned by an angle about an axis and its box center moved to A's box center plus an
# offset in units of A's box diagonal, so that the two overlap.
pairs=(
  "armadillo.off armadillo.off 30 1,2,0.5 0.05,0.03,-0.02"
  "bunny00.off bunny00.off 25 0,1,1 0.06,0.02,0.0"
  "ChineseDragon-10kv.off ChineseDragon-10kv.off 20 1,0,1 0.04,0.03,0.0"
  "refined_elephant.off refined_elephant.off 35 1,1,0 0.05,0.02,0.01"
  "turbine.off blade.off 10 0,0,1 0.0,0.05,0.0"
  "fandisk_large.off rotor_small.off 15 1,0,0 0.02,0.02,0.0"
)
place() {  # A B ANGLE AXIS OFFSET: prints B's pose "tx ty tz qw qx qy qz"
  python3 - "$root/data/meshes/$1" "$root/data/meshes/$2" "$3" "$4" "$5" <<'PY'
import math, sys
def box(path):
    words = open(path).read().split()
    i = 1 if words[0] == "OFF" else 0
    nv = int(words[i]); vals = [float(x) for x in words[i + 3:i + 3 + 3 * nv]]
    lo = [min(vals[k::3]) for k in range(3)]; hi = [max(vals[k::3]) for k in range(3)]
    return [(l + h) / 2 for l, h in zip(lo, hi)], math.dist(lo, hi)
ca, da = box(sys.argv[1]); cb, _ = box(sys.argv[2])
angle = float(sys.argv[3]) * math.pi / 180
axis = [float(x) for x in sys.argv[4].split(",")]; n = math.sqrt(sum(x * x for x in axis)); axis = [x / n for x in axis]
off = [float(x) for x in sys.argv[5].split(",")]
w, s = math.cos(angle / 2), math.sin(angle / 2)
x, y, z = (s * a for a in axis)
R = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
t = [ca[i] + off[i] * da - sum(R[i][j] * cb[j] for j in range(3)) for i in range(3)]
print(" ".join(repr(v) for v in t + [w, x, y, z]))
PY
}
declare -A poses
if [ "$queries" = 1 ]; then
  for p in "${pairs[@]}"; do
    read -r a b angle axis offset <<< "$p"
    poses["$a x $b"]="$(place "$a" "$b" "$angle" "$axis" "$offset")"
  done
fi

fail() { echo "compare_commits: $*" >&2; exit 1; }

run_scene() {  # BIN SCENE TAG ROUND: prints the run's median ms/step; round 0 keeps the contacts
  local bin="$1" scene="$2" tag="$3" round="$4" k="$steps"
  [ "$scene" = two_large ] && k=$(( steps / 3 > 0 ? steps / 3 : 1 ))
  local extra=()
  [ "$round" = 0 ] && extra=(--contacts "$work/$scene.$tag.jsonl")
  rm -f "$work/run.json"
  "$bin" run "$root/scenes/$scene.json" --method "$method" --threads "$threads" --steps "$k" \
    --json "$work/run.json" "${extra[@]}" >/dev/null 2>"$work/err" || return 1
  python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['summary']['median_step_ms'])" "$work/run.json"
}

run_query() {  # BIN A B TAG ROUND: the query's own query_ms; round 0 keeps the pairs
  rm -f "$work/query.json"
  "$1" query "$root/data/meshes/$2" "$root/data/meshes/$3" --pose-b "${poses[$2 x $3]}" --json 2>"$work/err" \
    > "$work/query.json" || return 1
  if [ "$5" = 0 ]; then
    python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['pairs'])" "$work/query.json" > "$work/$2 x $3.$4.jsonl"
  fi
  python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['stats']['query_ms'])" "$work/query.json"
}

declare -A times
for ((r = 0; r < rounds; r++)); do
  echo "compare_commits: round $((r + 1)) of $rounds" >&2
  for scene in "${scene_list[@]}"; do
    # Alternate which binary goes first, so that neither always meets a warm or a cold machine.
    for tag in $([ $((r % 2)) = 0 ] && echo "old new" || echo "new old"); do
      bin="$old_bin"; [ "$tag" = new ] && bin="$new_bin"
      ms="$(run_scene "$bin" "$scene" "$tag" "$r")" || fail "$tag binary failed on $scene: $(cat "$work/err")"
      times["$scene.$tag"]+="$ms "
    done
  done
  if [ "$queries" = 1 ]; then
    for p in "${pairs[@]}"; do
      read -r a b _ <<< "$p"
      for tag in $([ $((r % 2)) = 0 ] && echo "old new" || echo "new old"); do
        bin="$old_bin"; [ "$tag" = new ] && bin="$new_bin"
        ms="$(run_query "$bin" "$a" "$b" "$tag" "$r")" || fail "$tag binary failed on $a x $b: $(cat "$work/err")"
        times["$a x $b.$tag"]+="$ms "
      done
    done
  fi
done

# When the two files differ as bytes: whether they differ only by fields one version writes and the
# other does not (a contact's `depth` or the objects' names, added after 2a20389). Every contact (or
# pair) must be there in both, in the same order, and every field both have must be equal (JSON
# numbers parsed back to the same double). Prints "identical (shared fields; differ in ...)" and
# succeeds, or fails.
shared_fields_equal() {
  python3 - "$1" "$2" <<'PY'
import json, sys
def lines(path):
    with open(path) as f:
        return [json.loads(l) for l in f if l.strip()]
old, new = lines(sys.argv[1]), lines(sys.argv[2])
extra = set()
def same(a, b):
    if isinstance(a, dict) and isinstance(b, dict):
        shared = a.keys() & b.keys()
        extra.update((a.keys() ^ b.keys()))
        return (bool(shared) or a == b) and all(same(a[k], b[k]) for k in shared)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    return a == b and type(a) == type(b)
if len(old) != len(new) or not all(same(a, b) for a, b in zip(old, new)):
    sys.exit(1)
print("identical (shared fields; differ in " + ", ".join(sorted(extra)) + ")" if extra else "identical")
PY
}

status=0
echo "# $(git -C "$root" rev-parse --short HEAD)$(git -C "$root" diff --quiet || echo '+dirty') (new) vs $short (old), $rounds interleaved rounds, medians; steps: $method on $threads thread(s)"
echo "# machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) hardware threads"
printf '%-44s %12s %12s %8s  %s\n' case "old ms" "new ms" "new/old" contacts
cases=("${scene_list[@]}")
if [ "$queries" = 1 ]; then
  for p in "${pairs[@]}"; do read -r a b _ <<< "$p"; cases+=("$a x $b"); done
fi
for c in "${cases[@]}"; do
  same="-"
  if [ -f "$work/$c.old.jsonl" ]; then
    if cmp -s "$work/$c.old.jsonl" "$work/$c.new.jsonl"; then
      same="identical"
    elif same="$(shared_fields_equal "$work/$c.old.jsonl" "$work/$c.new.jsonl")"; then
      :
    else
      same="DIFFERENT"; status=1
    fi
  fi
  python3 - "$c" "${times[$c.old]}" "${times[$c.new]}" "$same" <<'EOF'
import statistics, sys
name, old, new, same = sys.argv[1], [float(x) for x in sys.argv[2].split()], [float(x) for x in sys.argv[3].split()], sys.argv[4]
mo, mn = statistics.median(old), statistics.median(new)
kind = "step" if " x " not in name else "query"
print(f"{name + ' (' + kind + ')':44s} {mo:12.3f} {mn:12.3f} {mn / mo:8.3f}  {same}")
EOF
done
exit $status
