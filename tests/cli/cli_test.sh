#!/usr/bin/env bash
# End-to-end checks of the caliber command line: output shape and exit codes.
set -u
cli="$1"
data="$2"
failures=0
passes=0
check() {  # check NAME EXPECTED_RC COMMAND... ; stderr/stdout kept in $out
  local name="$1" want="$2"
  shift 2
  out=$("$@" 2>&1)
  local rc=$?
  if [ "$rc" -ne "$want" ]; then
    echo "FAIL $name: exit $rc, wanted $want; output: $out"
    failures=$((failures + 1))
    return 1
  fi
  passes=$((passes + 1))
  return 0
}
contains() {  # contains NAME TEXT
  if ! grep -qF -- "$2" <<<"$out"; then
    echo "FAIL $1: output lacks '$2': $out"
    failures=$((failures + 1))
  else
    passes=$((passes + 1))
  fi
}

check help 0 "$cli" --help
check query-help 0 "$cli" query --help
check summary 0 "$cli" query "$data/tetra.off" "$data/tetra.off" --pose-b "0.5 0.5 0.5 1 0 0 0"
contains summary "intersecting triangle pairs"
check json 0 "$cli" query "$data/tetra.off" "$data/tetra_binary.stl" --pose-b "0.2 0.2 0.2 1 0 0 0" --kind proximity --tolerance 0.1 --json
contains json '"kind":"proximity"'
contains json '"stats":{'
contains json '"build_ms"'
python3 - "$out" <<'PY' || { echo "FAIL json-shape"; failures=$((failures + 1)); }
import json, sys
r = json.loads(sys.argv[1])
assert r["kind"] == "proximity"
assert r["pairs"] == sorted(r["pairs"]) and len(r["pairs"]) > 0
assert len(r["contacts"]) == len(r["pairs"])
for c, p in zip(r["contacts"], r["pairs"]):
    assert [c["tri_a"], c["tri_b"]] == p
    assert len(c["point_a"]) == 3 and len(c["normal"]) == 3 and c["distance"] <= 0.1
assert r["stats"]["node_tests"] >= r["stats"]["leaf_tests"] > 0
PY
# The engine's methods give caliber query the same pairs and contacts, bit for bit.
tmpq=$(mktemp -d)
for m in sequential stealing hybrid; do
  "$cli" query "$data/tetra.off" "$data/quad_fan.off" --pose-b "0.3 0.2 -0.2 0.9 0.1 0.3 0.2" --kind proximity \
    --tolerance 0.3 --method $m --threads 2 --json > "$tmpq/$m.json" 2>/dev/null
done
python3 - "$tmpq" <<'PY' && passes=$((passes + 1)) || { echo "FAIL query-methods"; failures=$((failures + 1)); }
import json, sys
r = {m: json.load(open(f"{sys.argv[1]}/{m}.json")) for m in ("sequential", "stealing", "hybrid")}
assert len(r["sequential"]["pairs"]) > 0
for m in ("stealing", "hybrid"):
    assert r[m]["pairs"] == r["sequential"]["pairs"], m
    assert r[m]["contacts"] == r["sequential"]["contacts"], m
PY
rm -rf "$tmpq"
# --repeat: the first run is reported as query_ms (cold), the median of the others as query_ms_warm.
check repeat 0 "$cli" query "$data/tetra.off" "$data/tetra_binary.stl" --pose-b "0.2 0.2 0.2 1 0 0 0" --kind contact --tolerance 0.1 --repeat 5 --json
python3 - "$out" <<'PY' && passes=$((passes + 1)) || { echo "FAIL repeat-shape: $out"; failures=$((failures + 1)); }
import json, sys
s = json.loads(sys.argv[1])["stats"]
assert s["repeat"] == 5 and s["query_ms"] > 0 and s["query_ms_warm"] > 0, s
PY
check repeat-summary 0 "$cli" query "$data/tetra.off" "$data/tetra.off" --pose-b "0.5 0.5 0.5 1 0 0 0" --repeat 3
contains repeat-summary "median of the other 2"
check repeat-zero 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --repeat 0
contains repeat-zero "--repeat"
check repeat-absurd 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --repeat 1000000
check bad-method 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --method turbo
contains bad-method "unknown method"
check missing 2 "$cli" query "$data/nope.off" "$data/tetra.off"
contains missing "nope.off: no such file"
check bad-index 2 "$cli" query "$data/bad/index_range.off" "$data/tetra.off"
contains bad-index "index_range.off"
check nan 2 "$cli" query "$data/bad/nan.off" "$data/tetra.off"
contains nan "non-finite"
check empty 2 "$cli" query "$data/bad/empty.off" "$data/tetra.off"
check directory 2 "$cli" query "$data/bad" "$data/tetra.off"
check bad-pose 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --pose-a "1 2 3"
contains bad-pose "--pose-a"
check zero-quat 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --pose-b "0 0 0 0 0 0 0"
check bad-kind 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --kind collide
contains bad-kind "unknown query kind"
check neg-tol 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --kind proximity --tolerance -1
check bad-angle 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --kind contact --angle 200
check no-args 2 "$cli"
check unknown-flag 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --frobnicate

# caliber run
tmp=$(mktemp -d)
check run 0 "$cli" run "$data/scenes/tetras.json" --json "$tmp/report.json" --contacts "$tmp/contacts.jsonl"
contains run "summary over 12 steps"
contains run "heaviest pair"
python3 - "$tmp/report.json" "$tmp/contacts.jsonl" <<'PY' || { echo "FAIL run-files"; failures=$((failures + 1)); }
import json, sys
r = json.load(open(sys.argv[1]))
assert r["scene"] == "tetras" and len(r["steps"]) == 12
s = r["steps"][0]
for key in ("broad_ms", "narrow_ms", "reduce_ms", "node_tests", "contacts", "tasks"):
    assert key in s, key
assert r["summary"]["steps_with_contacts"] > 0
lines = open(sys.argv[2]).read().splitlines()
assert len(lines) == 12
counts = [len(json.loads(l)["contacts"]) for l in lines]
assert counts == [st["contacts"] for st in r["steps"]]
PY
check run-steps 0 "$cli" run "$data/scenes/tetras.json" --steps 3
contains run-steps "summary over 3 steps"
check run-zero-steps 2 "$cli" run "$data/scenes/tetras.json" --steps 0
check run-missing 2 "$cli" run "$data/scenes/nope.json"
contains run-missing "no such scene file"
check run-bad-key 2 "$cli" run "$data/scenes/bad_key.json"
contains run-bad-key "'objects[0].wobble': unknown key"
check run-directory 2 "$cli" run "$data/scenes"
# A scene whose mesh is the scene file itself; thread counts out of range.
selfdir=$(mktemp -d)
echo '{"objects": [{"mesh": "self.json"}, {"mesh": "self.json", "position": [0.1, 0, 0]}]}' > "$selfdir/self.json"
check run-self 2 "$cli" run "$selfdir/self.json"
contains run-self "self.json: cannot parse mesh"
rm -rf "$selfdir"
check run-threads-negative 2 "$cli" run "$data/scenes/tetras.json" --threads -1
contains run-threads-negative "threads: must be between 1 and 1024"
check run-threads-absurd 2 "$cli" run "$data/scenes/tetras.json" --threads 5000 --method hybrid
check query-threads-absurd 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --threads 100000 --method stealing
check run-threads-zero 0 "$cli" run "$data/scenes/tetras.json" --threads 0 --method hybrid --steps 2
check query-far-pose 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --pose-b "1e300 0 0 1 0 0 0"
contains query-far-pose "beyond +-1e15"
# caliber refine
check refine 0 "$cli" refine "$data/tetra.off" "$tmp/fine.off" --levels 2
contains refine "4 triangles"
contains refine "64 triangles"
check refine-query 0 "$cli" query "$tmp/fine.off" "$data/tetra.off" --show 0
check refine-bad-levels 2 "$cli" refine "$data/tetra.off" "$tmp/x.off" --levels 12
check refine-missing 2 "$cli" refine "$data/nope.off" "$tmp/x.off"
# caliber bench: a tiny run writes the report and the raw figures; bad options fail before any work.
check bench 0 "$cli" bench "$data/scenes/tetras.json" --steps 4 --repeat 2 --threads 1,2 --simulate 4 --no-fcl --no-figures --out "$tmp/bench"
contains bench "wrote $tmp/bench/report.md"
python3 - "$tmp/bench" <<'PY' || { echo "FAIL bench-files"; failures=$((failures + 1)); }
import json, sys
d = sys.argv[1]
r = json.load(open(d + "/results.json"))
assert r["contacts_identical"] is True
assert r["threads"] == [1, 2] and r["repeat"] == 2
(s,) = r["scenes"]
assert s["name"] == "tetras" and s["steps"] == 4
assert set(s["methods"]) == {"sequential", "exploitation", "stealing", "aposteriori", "apriori", "hybrid"}
assert list(s["methods"]["sequential"]["threads"]) == ["1"]
for m, v in s["methods"].items():
    for t, run in v["threads"].items():
        assert len(run["runs_ms"]) == 2 and run["step_ms"] > 0, (m, t)
        if m != "sequential":  # the run's own tasks list-scheduled on as many cores as threads
            b = run["phases_per_step"]["balance_speedup"]
            assert 1.0 <= b <= int(t) + 1e-9, (m, t, b)
            if t == "1":
                assert abs(b - 1.0) < 1e-9, (m, b)
    if m != "sequential":
        assert set(v["simulated_speedup"]) == {"4"}, m
assert s["table1"]["objects"] == 2
assert set(r["gantt"]["methods"]) == {"exploitation", "hybrid"}
report = open(d + "/report.md").read()
for heading in ("## Table 1", "## Table 2", "## One-thread overhead", "## Simulated speed-up", "## Targets", "**all identical**"):
    assert heading in report, heading
PY
check bench-missing 2 "$cli" bench "$data/scenes/nope.json" --out "$tmp/bench2"
contains bench-missing "nope.json"
check bench-bad-method 2 "$cli" bench "$data/scenes/tetras.json" --methods sequential,turbo --out "$tmp/bench2"
check bench-bad-threads 2 "$cli" bench "$data/scenes/tetras.json" --threads 0 --out "$tmp/bench2"
check bench-bad-repeat 2 "$cli" bench "$data/scenes/tetras.json" --repeat 0 --out "$tmp/bench2"
rm -rf "$tmp"

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
