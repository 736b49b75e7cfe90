#!/usr/bin/env bash
# End-to-end checks of the caliber command line: output shape and exit codes.
set -u
cli="$1"
bench="$(dirname "$cli")/caliber-bench"  # the benchmark program, built beside caliber
data="$2"
source "$(dirname "$0")/check_lib.sh"

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
check first-and-max-pairs 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --first --max-pairs 3
contains first-and-max-pairs "caliber: --first: is --max-pairs 1: give --first or --max-pairs, not both"
check first-alone 0 "$cli" query "$data/tetra.off" "$data/tetra.off" --pose-b "0.2 0.2 0.2 1 0 0 0" --kind proximity --tolerance 0.1 --first --json
python3 -c "import json, sys; r = json.loads(sys.argv[1]); assert len(r['pairs']) == 1 and r['limit_reached']" "$out" &&
  passes=$((passes + 1)) || { echo "FAIL first-alone: $out"; failures=$((failures + 1)); }
check neg-tol 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --kind proximity --tolerance -1
check bad-angle 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --kind contact --angle 200
check no-args 2 "$cli"
check unknown-flag 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --frobnicate

# The distance query: the closest pair, a bound that answers "not closer than d", the same answer
# from every engine method on a scene, and through the engine without a tolerance as without it.
check distance 0 "$cli" query "$data/tetra.off" "$data/tetra.off" --pose-b "2 0.1 0 1 0 0 0" --kind distance --json
python3 - "$out" <<'PY' || { echo "FAIL distance-json"; failures=$((failures + 1)); }
import json, math, sys
r = json.loads(sys.argv[1])
assert r["kind"] == "distance" and len(r["pairs"]) == 1 and len(r["contacts"]) == 1
c = r["contacts"][0]
assert 0.9 < c["distance"] < 2.0 and abs(math.dist(c["point_a"], c["point_b"]) - c["distance"]) < 1e-12
PY
check distance-bounded 0 "$cli" query "$data/tetra.off" "$data/tetra.off" --pose-b "2 0.1 0 1 0 0 0" --kind distance --tolerance 0.5
contains distance-bounded "none within the tolerance 0.5"
check distance-engine-unbounded 0 "$cli" query "$data/tetra.off" "$data/tetra.off" --pose-b "2 0.1 0 1 0 0 0" --kind distance --json --method hybrid
unbounded_hybrid="$out"
check distance-engine-unbounded 0 "$cli" query "$data/tetra.off" "$data/tetra.off" --pose-b "2 0.1 0 1 0 0 0" --kind distance --json
python3 - "$unbounded_hybrid" "$out" <<'PY' || { echo "FAIL distance-engine-unbounded: not the query's answer"; failures=$((failures + 1)); }
import json, sys
a, b = json.loads(sys.argv[1]), json.loads(sys.argv[2])
assert a["contacts"] == b["contacts"] and len(a["contacts"]) == 1, (a, b)
PY
# Intersecting meshes (a tetrahedron and an octahedron: 32 triangle pairs, traversed): distance 0
# on the traversal's first intersecting pair, the same through the engine; --lowest-ids reports
# the lowest ids at 0 (never higher than the first pair's).
check distance-contact 0 "$cli" query "$data/tetra.off" "$data/octahedron.off" --pose-b "0.2 0.2 0.2 1 0 0 0" --kind distance --json
first="$out"
check distance-contact-engine 0 "$cli" query "$data/tetra.off" "$data/octahedron.off" --pose-b "0.2 0.2 0.2 1 0 0 0" --kind distance --json --method apriori --threads 2
engine="$out"
check distance-lowest-ids 0 "$cli" query "$data/tetra.off" "$data/octahedron.off" --pose-b "0.2 0.2 0.2 1 0 0 0" --kind distance --json --lowest-ids
python3 - "$first" "$engine" "$out" <<'PY' || { echo "FAIL distance-contact"; failures=$((failures + 1)); }
import json, sys
first, engine, lowest = (json.loads(a) for a in sys.argv[1:])
assert first["contacts"] == engine["contacts"] and len(first["contacts"]) == 1, (first, engine)
f, l = first["contacts"][0], lowest["contacts"][0]
assert f["distance"] == 0 and l["distance"] == 0, (f, l)
assert first["pairs"][0] >= lowest["pairs"][0], (first["pairs"], lowest["pairs"])
PY
check distance-negative 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --kind distance --tolerance -1
dtmp=$(mktemp -d)
for m in sequential exploitation stealing aposteriori apriori hybrid; do
  check "distance-run-$m" 0 "$cli" run "$data/scenes/distance_tetras.json" --method "$m" --threads 2 --contacts "$dtmp/$m.jsonl"
done
for m in exploitation stealing aposteriori apriori hybrid; do
  cmp -s "$dtmp/sequential.jsonl" "$dtmp/$m.jsonl" && passes=$((passes + 1)) || { echo "FAIL distance-run: $m differs"; failures=$((failures + 1)); }
done
grep -q '"distance"' "$dtmp/sequential.jsonl" && passes=$((passes + 1)) || { echo "FAIL distance-run: no contacts"; failures=$((failures + 1)); }
rm -rf "$dtmp"

# --first and --max-pairs: stopped at the limit, flagged; a limit the answer does not reach changes nothing.
check first 0 "$cli" query "$data/tetra.off" "$data/quad_fan.off" --pose-b "0.2 0.2 0.3 0 1 0 0" --first --json
python3 - "$out" <<'PY' || { echo "FAIL first-json"; failures=$((failures + 1)); }
import json, sys
r = json.loads(sys.argv[1])
assert len(r["pairs"]) == 1 and r["limit_reached"] is True, r
PY
check max-pairs 0 "$cli" query "$data/tetra.off" "$data/quad_fan.off" --pose-b "0.2 0.2 0.3 0 1 0 0" --max-pairs 3
contains max-pairs "limit reached: the query stopped at 3 pairs"
check max-pairs-roomy 0 "$cli" query "$data/tetra.off" "$data/quad_fan.off" --pose-b "0.2 0.2 0.3 0 1 0 0" --max-pairs 1000 --json
contains max-pairs-roomy '"limit_reached":false'
check max-pairs-negative 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --max-pairs -1
mtmp=$(mktemp -d)
check run-max-pairs 0 "$cli" run "$data/scenes/view_tetras.json" --max-pairs 1 --contacts "$mtmp/c.jsonl" --json "$mtmp/r.json"
contains run-max-pairs "reached max_pairs 1 (--max-pairs) on some pair"
python3 - "$mtmp/c.jsonl" "$mtmp/r.json" <<'PY' || { echo "FAIL run-max-pairs-files"; failures=$((failures + 1)); }
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
assert any(l["limit_reached"] for l in lines)
for l in lines:
    per_pair = {}
    for c in l["contacts"]:
        per_pair[(c["object_a"], c["object_b"])] = per_pair.get((c["object_a"], c["object_b"]), 0) + 1
    assert all(n <= 1 for n in per_pair.values()), per_pair
r = json.load(open(sys.argv[2]))
assert [s["limit_reached"] for s in r["steps"]] == [l["limit_reached"] for l in lines]
PY
sed 's/"tolerance": 0.02}/"tolerance": 0.02, "max_pairs": -3}/; s#"\.\./tetra.off"#"'"$data"'/tetra.off"#g' "$data/scenes/view_tetras.json" > "$mtmp/bad.json"
check scene-bad-max-pairs 2 "$cli" run "$mtmp/bad.json"
contains scene-bad-max-pairs "query.max_pairs"
rm -rf "$mtmp"

# caliber run
tmp=$(mktemp -d)
check run 0 "$cli" run "$data/scenes/tetras.json" --json "$tmp/report.json" --contacts "$tmp/contacts.jsonl"
contains run "summary over 12 steps"
contains run "heaviest pair"
contains run "distinct pairs over the run"
contains run "method stealing on"  # the default: caliber::kDefaultMethod on the hardware threads
python3 - "$tmp/report.json" "$tmp/contacts.jsonl" <<'PY' || { echo "FAIL run-files"; failures=$((failures + 1)); }
import json, sys
r = json.load(open(sys.argv[1]))
assert r["scene"] == "tetras" and len(r["steps"]) == 12
s = r["steps"][0]
for key in ("broad_ms", "narrow_ms", "reduce_ms", "node_tests", "contacts", "pairs"):
    assert key in s, key
assert r["schema_version"] == 2
assert all(set(p) == {"a", "b", "node_tests", "leaf_tests", "contacts", "limit_reached"} for st in r["steps"] for p in st["pairs"])
assert sum(p["contacts"] for p in s["pairs"]) == s["contacts"] or s["limit_reached"]
assert r["summary"]["steps_with_contacts"] > 0
assert r["summary"]["distinct_pairs"] >= max(len(st["pairs"]) for st in r["steps"])
lines = open(sys.argv[2]).read().splitlines()
assert len(lines) == 12
counts = [len(json.loads(l)["contacts"]) for l in lines]
assert counts == [st["contacts"] for st in r["steps"]]
PY
check run-steps 0 "$cli" run "$data/scenes/tetras.json" --steps 3
contains run-steps "summary over 3 steps"
check run-zero-steps 2 "$cli" run "$data/scenes/tetras.json" --steps 0
# -1 is how the program marks "the scene's steps"; given, it is a bad value like any negative.
check query-negative-show 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --show -2
contains query-negative-show "must be a whole number >= 0"
check run-negative-steps 2 "$cli" run "$data/scenes/tetras.json" --steps -1
contains run-negative-steps "steps"
check run-missing 2 "$cli" run "$data/scenes/nope.json"
contains run-missing "no such scene file"
check run-bad-key 2 "$cli" run "$data/scenes/bad_key.json"
contains run-bad-key "'objects[0].wobble': unknown key"
check run-directory 2 "$cli" run "$data/scenes"
# A scene whose mesh is the scene file itself; thread counts out of range.
selfdir=$(mktemp -d)
echo '{"objects": [{"mesh": "self.json"}, {"mesh": "self.json", "position": [0.1, 0, 0]}]}' > "$selfdir/self.json"
check run-self 2 "$cli" run "$selfdir/self.json"
contains run-self "self.json: extension '.json' is not a mesh format caliber reads"
rm -rf "$selfdir"
check run-threads-negative 2 "$cli" run "$data/scenes/tetras.json" --threads -1
contains run-threads-negative "threads: must be between 0 and 1024"
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
# The benchmark is a program of its own: caliber has no bench command and none of its code.
check no-bench-command 2 "$cli" bench "$data/scenes/tetras.json"
if nm -C "$cli" 2>/dev/null | grep -qE "run_bench|add_bench_options|bench_records|write_bench_report|machine_description"; then
  echo "FAIL no-bench-symbols: caliber holds the bench's code"; failures=$((failures + 1))
else
  passes=$((passes + 1))
fi
# caliber-bench: a tiny run writes the report, the raw figures and the SVG figures; bad options fail
# before any work.
check bench 0 "$bench" "$data/scenes/tetras.json" --steps 4 --repeat 2 --threads 1,2 --simulate 4 --no-fcl --out "$tmp/bench"
contains bench "wrote $tmp/bench/report.md and results.json and figures"
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
        # The cut for 4 threads run on one, its pieces timed and replayed on 4 cores.
        p = v["predicted"]["4"]
        assert set(v["predicted"]) == {"4"} and p["step_ms"] > 0 and p["sequential_step_ms"] > 0, m
        assert abs(p["speedup"] - p["sequential_step_ms"] / p["step_ms"]) < 1e-9 * p["speedup"], m
assert s["table1"]["objects"] == 2
assert set(r["gantt"]["methods"]) == {"exploitation", "hybrid"}
assert set(s["ceiling"]) == {"2"} and len(s["ceiling"]["2"]["copy_step_ms"]) == 2 and s["ceiling"]["2"]["ceiling_speedup"] > 0
assert r["runs_done"] == r["runs_planned"] == 2 * (1 + 5 * 2) and "stopped" not in r
report = open(d + "/report.md").read()
for heading in ("## Table 1", "## Table 2", "## The machine's ceiling", "## One-thread overhead", "## Simulated speed-up",
                "## Predicted from measured time per piece", "## Measured figures", "**all identical**", "Runs done: 22 of 22"):
    assert heading in report, heading
# The log: one record per line, as measured; every run is there.
records = [json.loads(line) for line in open(d + "/runs.jsonl")]
assert records[0]["kind"] == "header"
assert sum(1 for x in records if x["kind"] == "run") == 22
PY
# The figures: well-formed SVG, drawn from the results (a solid line and a legend entry per measured
# method, a dashed line per simulated one, every point inside the page), linked from the report.
python3 - "$tmp/bench" <<'PY' && passes=$((passes + 1)) || { echo "FAIL bench-figures"; failures=$((failures + 1)); }
import json, os, sys, xml.dom.minidom
d = sys.argv[1]
r = json.load(open(d + "/results.json"))
(s,) = r["scenes"]
methods = sorted(m for m in s["methods"] if m != "sequential")
has_points = any(s["methods"].get(m, {}).get("correlation", {}).get("points") for m in ("apriori", "hybrid", "hybrid+history"))
names = ["speedup_tetras.svg", "gantt.svg"] + (["correlation.svg"] if has_points else [])
assert sorted(f for f in os.listdir(d) if f.endswith((".svg", ".png"))) == sorted(names), os.listdir(d)
def parse(name):
    doc = xml.dom.minidom.parse(os.path.join(d, name)).documentElement
    assert doc.tagName == "svg" and doc.getAttribute("font-family") == "sans-serif", name
    w, h = float(doc.getAttribute("width")), float(doc.getAttribute("height"))
    for line in doc.getElementsByTagName("polyline"):
        for xy in line.getAttribute("points").split():
            x, y = map(float, xy.split(","))
            assert 0 <= x <= w and 0 <= y <= h, (name, x, y)
    return doc, [t.firstChild.data for t in doc.getElementsByTagName("text") if t.firstChild]
doc, texts = parse("speedup_tetras.svg")
lines = doc.getElementsByTagName("polyline")
solid = [l for l in lines if not l.getAttribute("stroke-dasharray")]
assert len(solid) == len(methods), (len(solid), methods)
assert len(lines) == 1 + 2 * len(methods), len(lines)  # the linear limit, measured and simulated per method
assert [t for t in texts if t.endswith(" (measured)")] == [m + " (measured)" for m in methods], texts
assert "speed-up over sequential" in texts and any(t.startswith("tetras: sequential ") for t in texts), texts
assert {"1", "2", "4"} <= set(texts), texts  # log2 ticks
doc, texts = parse("gantt.svg")
assert sorted(t.split(":")[0] for t in texts if ": tetras step " in t) == ["exploitation", "hybrid"], texts
assert {"weight-driven stage", "depth-first", "finalization", "thread 0", "thread 1"} <= set(texts), texts
assert doc.getElementsByTagName("path"), "no bars"
if has_points:
    doc, texts = parse("correlation.svg")
    assert any(t.startswith("tetras, ") and ": r = " in t for t in texts), texts
report = open(d + "/report.md").read()
for name in names:
    assert "](" + name + ")" in report, name
PY
# The report and the figures rebuilt from the log alone are the same, byte for byte; from a log cut
# in the middle of a line, a report of the runs it holds.
check bench-from-log 0 "$bench" --from-log "$tmp/bench/runs.jsonl" --out "$tmp/bench-again"
python3 - "$tmp/bench" "$tmp/bench-again" <<'PY' && passes=$((passes + 1)) || { echo "FAIL bench-from-log-same"; failures=$((failures + 1)); }
import os, sys
a, b = sys.argv[1:]
names = sorted(f for f in os.listdir(a) if f.endswith(".svg")) + ["report.md"]
assert sorted(f for f in os.listdir(b) if f.endswith(".svg")) + ["report.md"] == names, os.listdir(b)
for name in names:
    assert open(os.path.join(a, name), "rb").read() == open(os.path.join(b, name), "rb").read(), name
PY
# A tetras run has no correlation points: a log given some draws correlation.svg, a panel per
# calibrated method with its r, every point (a zero clamped onto the log axes) a dot.
python3 - "$tmp/bench/runs.jsonl" "$tmp/corr.jsonl" <<'PY'
import json, sys
with open(sys.argv[2], "w") as out:
    for line in open(sys.argv[1]):
        r = json.loads(line)
        if r["kind"] == "simulation" and r["method"] in ("apriori", "hybrid"):
            r["correlation"] = {"cores": r["cores"], "pearson": 0.5, "tasks": 4, "points": [[0, 0], [1.5, 3], [20, 10], [300, 400]]}
        out.write(json.dumps(r) + "\n")
PY
check bench-from-log-correlation 0 "$bench" --from-log "$tmp/corr.jsonl" --out "$tmp/bench-corr"
python3 - "$tmp/bench-corr/correlation.svg" <<'PY' && passes=$((passes + 1)) || { echo "FAIL bench-correlation-figure"; failures=$((failures + 1)); }
import sys, xml.dom.minidom
doc = xml.dom.minidom.parse(sys.argv[1]).documentElement
texts = [t.firstChild.data for t in doc.getElementsByTagName("text") if t.firstChild]
assert [t for t in texts if ": r = " in t] == ["tetras, apriori: r = 0.50", "tetras, hybrid: r = 0.50"], texts
dots = [p for p in doc.getElementsByTagName("path") if p.getAttribute("stroke-linecap") == "round"]
assert [p.getAttribute("d").count("M") for p in dots] == [4, 4], [p.getAttribute("d") for p in dots]
assert {"0.1", "1", "10", "100"} <= set(texts), texts  # log10 ticks
PY
head -c 2500 "$tmp/bench/runs.jsonl" > "$tmp/cut.jsonl"
check bench-from-cut-log 0 "$bench" --from-log "$tmp/cut.jsonl" --out "$tmp/bench-cut" --no-figures
contains bench-from-cut-log "wrote $tmp/bench-cut/report.md"
grep -q "the log ends before the run did" "$tmp/bench-cut/report.md" && passes=$((passes + 1)) ||
  { echo "FAIL bench-cut-report"; failures=$((failures + 1)); }
# A budget too small for the whole run: it stops between runs, inside the budget, and says so.
# run --continuous: each step's motion to the next swept; the pairs that touch between steps.
check run-continuous 0 "$cli" run "$data/../../scenes/funnel.json" --continuous --steps 6 --threads 2
contains run-continuous "summary over 5 step intervals"
contains run-continuous "pairs that touch"
# --json: the report of every interval, the same pairs and times whatever the threads.
ctmp=$(mktemp -d)
check run-continuous-json 0 "$cli" run "$data/../../scenes/funnel.json" --continuous --steps 6 --threads 1 --json "$ctmp/one.json"
check run-continuous-json 0 "$cli" run "$data/../../scenes/funnel.json" --continuous --steps 6 --threads 2 --json "$ctmp/two.json"
python3 - "$ctmp/one.json" "$ctmp/two.json" <<'PY' || { echo "FAIL run-continuous-json"; failures=$((failures + 1)); }
import json, sys
one, two = (json.load(open(f)) for f in sys.argv[1:])
strip = lambda r: [[p for p in i["pairs"]] for i in r["intervals"]]
assert strip(one) == strip(two), "the threads changed a sweep"
assert [i["step"] for i in one["intervals"]] == list(range(5)) and one["summary"]["intervals"] == 5
pairs = [p for i in one["intervals"] for p in i["pairs"]]
assert pairs and one["summary"]["pairs_touching"] == sum(p["status"] == "contact" for p in pairs)
for p in pairs:
    assert p["a"] < p["b"] and 0.0 <= p["time"] <= 1.0 and p["queries"] >= 1, p
    assert p["status"] != "contact" or (p["distance"] >= 0.0 and len(p["point_a"]) == 3), p
assert one["summary"]["first_contact_step"] == min(i["step"] + p["time"] for i in one["intervals"] for p in i["pairs"])
PY
check run-continuous-json-scene 2 "$cli" run "$data/../../scenes/funnel.json" --continuous --json "$data/../../scenes/funnel.json"
contains run-continuous-json-scene "--json"
rm -rf "$ctmp"
check run-continuous-contacts 2 "$cli" run "$data/../../scenes/funnel.json" --continuous --contacts "$(mktemp -u)"
contains run-continuous-contacts "--continuous"
check run-continuous-tolerance 2 "$cli" run "$data/../../scenes/funnel.json" --continuous --sweep-tolerance -1
contains run-continuous-tolerance "tolerance"
# (two_small: its runs take long enough; its meshes are extracted by scripts/fetch_meshes.sh before the tests)
check bench-budget 0 "$bench" "$data/../../scenes/two_small.json" --steps 100 --repeat 3 --threads 1,2 --simulate 4 --no-fcl \
  --no-figures --budget-s 1 --out "$tmp/bench-budget"
contains bench-budget "--budget-s 1 reached"
python3 - "$tmp/bench-budget" <<'PY' && passes=$((passes + 1)) || { echo "FAIL bench-budget-files"; failures=$((failures + 1)); }
import json, sys
r = json.load(open(sys.argv[1] + "/results.json"))
# Checked between runs and, within a run, after each step (a step is ~4 ms): the stop comes inside
# the budget, give or take a step on a busy machine, unless loading the scene alone took longer
# (as under AddressSanitizer), when it comes at the first check, before any run is finished.
assert r["stopped"]["reason"] == "budget", r["stopped"]
assert r["stopped"]["after_s"] <= 1.5 or r["runs_done"] == 0, (r["stopped"], r["runs_done"])
assert r["runs_done"] < r["runs_planned"], (r["runs_done"], r["runs_planned"])
assert "cut short by its time budget" in open(sys.argv[1] + "/report.md").read()
PY
# A budget spent before the sequential reference finished: the report still says so (written whole).
check bench-budget-nothing 0 "$bench" "$data/scenes/tetras.json" --steps 100000 --repeat 1 --threads 1 --simulate 2 --no-fcl \
  --no-figures --budget-s 0.001 --out "$tmp/bench-nothing"
grep -q "nothing to report yet" "$tmp/bench-nothing/report.md" && passes=$((passes + 1)) ||
  { echo "FAIL bench-budget-nothing-report"; failures=$((failures + 1)); }
echo "not json" > "$tmp/bad.jsonl"
touch "$tmp/a-file"
check bench-bad-log 2 "$bench" --from-log "$tmp/bad.jsonl" --out "$tmp/bench3"
contains bench-bad-log "line 1 is not a bench record"
# A record with a field missing or of the wrong type, or naming a scene the header lacks: exit 2,
# naming the file and the line.
python3 - "$tmp/bench/runs.jsonl" "$tmp" <<'PY'
import json, sys
lines = open(sys.argv[1]).read().splitlines()
run = next(i for i, l in enumerate(lines) if json.loads(l)["kind"] == "run")
for name, change in (("nofield", lambda r: r.pop("total_ms")), ("badtype", lambda r: r.__setitem__("threads", "two")),
                     ("badscene", lambda r: r.__setitem__("scene", "elsewhere"))):
    r = json.loads(lines[run])
    change(r)
    open(f"{sys.argv[2]}/{name}.jsonl", "w").write("\n".join(lines[:run] + [json.dumps(r)] + lines[run + 1:]) + "\n")
PY
check bench-log-nofield 2 "$bench" --from-log "$tmp/nofield.jsonl" --out "$tmp/bench3"
contains bench-log-nofield 'no "total_ms"'
check bench-log-badtype 2 "$bench" --from-log "$tmp/badtype.jsonl" --out "$tmp/bench3"
contains bench-log-badtype '"threads" has the wrong type'
check bench-log-badscene 2 "$bench" --from-log "$tmp/badscene.jsonl" --out "$tmp/bench3"
contains bench-log-badscene "names a scene the header does not list"
check bench-from-log-out-file 2 "$bench" --from-log "$tmp/bench/runs.jsonl" --out "$tmp/a-file"
check bench-missing-log 2 "$bench" --from-log "$tmp/none.jsonl"
check bench-bad-budget 2 "$bench" "$data/scenes/tetras.json" --budget-s -5 --out "$tmp/bench2"
check bench-out-file 2 "$bench" "$data/scenes/tetras.json" --out "$tmp/a-file"
contains bench-out-file "not a folder"
check bench-missing 2 "$bench" "$data/scenes/nope.json" --out "$tmp/bench2"
contains bench-missing "nope.json"
check bench-bad-method 2 "$bench" "$data/scenes/tetras.json" --methods sequential,turbo --out "$tmp/bench2"
check bench-bad-threads 2 "$bench" "$data/scenes/tetras.json" --threads 0 --out "$tmp/bench2"
check bench-bad-repeat 2 "$bench" "$data/scenes/tetras.json" --repeat 0 --out "$tmp/bench2"
rm -rf "$tmp"

# Bad inputs (docs/bad_input.md): readers by extension, linear adjacency, exact range,
# memory, outputs that are never lost, SIGINT.
r2=$(mktemp -d)
asan=0
ldd "$cli" 2>/dev/null | grep -q libasan && asan=1
cp "$data/tetra.off" "$r2/tetra.ase"
check ext-ase 2 "$cli" query "$r2/tetra.ase" "$data/tetra.off"
contains ext-ase "extension '.ase' is not a mesh format caliber reads"
contains ext-ase ".off, .ply, .obj and .stl"
cp "$data/tetra.off" "$r2/noext"
check ext-none 2 "$cli" query "$r2/noext" "$data/tetra.off"
contains ext-none "has no extension"
cp "$data/tetra.off" "$r2/UPPER.OFF"
check ext-upper 0 "$cli" query "$r2/UPPER.OFF" "$data/tetra.off"
printf 'OFF3 2 0\n0 0 0\n1 1 1\n' > "$r2/variant.off"
check off-variant 2 "$cli" query "$r2/variant.off" "$data/tetra.off"
contains off-variant "unsupported OFF variant 'OFF3'"
printf 'PLY\nformat ascii 1.0\nend_header\n' > "$r2/upper.ply"
check ply-upper-magic 2 "$cli" query "$r2/upper.ply" "$data/tetra.off"
contains ply-upper-magic "starts with the line 'ply'"
printf '<?xml version="1.0"?><COLLADA></COLLADA>\n' > "$r2/scene.dae"
check ext-dae 2 "$cli" query "$r2/scene.dae" "$data/tetra.off"
printf '\xef\xbb\xbfOFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n3 0 2 3\n3 1 2 3\n' > "$r2/bom.off"
check off-bom 0 "$cli" query "$r2/bom.off" "$data/tetra.off"
printf 'OFF\r4 4 0\r0 0 0\r1 0 0\r0 1 0\r0 0 1\r3 0 1 2\r3 0 1 3\r3 0 2 3\r3 1 2 3\r' > "$r2/cr.off"
check off-cr-only 0 "$cli" query "$r2/cr.off" "$data/tetra.off"
printf 'OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n3 0 2 3\n3 1 2 x\0y\n' > "$r2/nul.off"
check off-nul 2 "$cli" query "$r2/nul.off" "$data/tetra.off"
contains off-nul "'x\x00y' is not a vertex index"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar float vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0.9 1 2\n' > "$r2/float_index.ply"
check ply-float-index 2 "$cli" query "$r2/float_index.ply" "$data/tetra.off"
contains ply-float-index "vertex indices must have an integer type"
# One polygon of 100,000 corners: linear adjacency, answered (was quadratic: ~40 GB).
python3 - "$r2/fan.off" <<'PY'
import math, sys
n = 100000
with open(sys.argv[1], "w") as f:
    f.write(f"OFF\n{n} 1 0\n")
    for i in range(n):
        a = 2 * math.pi * i / n
        f.write(f"{math.cos(a)!r} {math.sin(a)!r} 0\n")
    f.write(f"{n} " + " ".join(map(str, range(n))) + "\n")
PY
if [ "$asan" = 0 ]; then
  check huge-polygon 0 bash -c "ulimit -v 2000000; exec \"\$0\" query \"\$1\" \"\$1\" --kind contact --tolerance 0.01 --pose-b '0 0 0.005 1 0 0 0'" "$cli" "$r2/fan.off"
else
  check huge-polygon 0 "$cli" query "$r2/fan.off" "$r2/fan.off" --kind contact --tolerance 0.01 --pose-b "0 0 0.005 1 0 0 0"
fi
contains huge-polygon "contacts"
# Every reader under a small address space: the test files load; files that announce billions of
# elements fail before allocating them.
printf 'OFF\n2000000000 2000000000 0\n0 0 0\n' > "$r2/bomb.off"
printf 'ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n' > "$r2/bomb.ply"
python3 -c "import struct, sys; open(sys.argv[1], 'wb').write(b'\0' * 80 + struct.pack('<I', 4000000000))" "$r2/bomb.stl"
if [ "$asan" = 0 ]; then
  for f in tetra.off tetra.ply tetra.obj tetra_ascii.stl tetra_binary.stl; do
    check "reader-ulimit-$f" 0 bash -c "ulimit -v 400000; exec \"\$0\" query \"\$1\" \"\$1\" --kind contact --tolerance 0.1" "$cli" "$data/$f"
  done
  for f in bomb.off bomb.ply bomb.stl; do
    check "reader-bomb-$f" 2 bash -c "ulimit -v 400000; exec \"\$0\" query \"\$1\" \"\$1\"" "$cli" "$r2/$f"
  done
fi
# Coordinates below 2^-120: refused, naming the file and the range.
printf 'OFF\n3 1 0\n0 0 0\n1e-40 0 0\n0 1e-40 0\n3 0 1 2\n' > "$r2/tiny.off"
check tiny-coordinates 2 "$cli" query "$r2/tiny.off" "$r2/tiny.off"
contains tiny-coordinates "tiny.off: vertex 1 has a coordinate of magnitude 1e-40, below 2^-120"
check tiny-tolerance 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --kind proximity --tolerance 1e-40
# Scene: a huge tolerance names the file and the key; a huge quaternion is the same rotation.
mkdir -p "$r2/s"
cp "$data/tetra.off" "$r2/s/tetra.off"
echo '{"query": {"kind": "proximity", "tolerance": 1e16}, "objects": [{"mesh": "tetra.off"}]}' > "$r2/s/tol.json"
check scene-huge-tolerance 2 "$cli" run "$r2/s/tol.json"
contains scene-huge-tolerance "tol.json: 'query.tolerance': must be at most 1e15"
for q in "1, 0, 0, 1" "1e200, 0, 0, 1e200"; do
  echo '{"steps": 1, "objects": [{"mesh": "tetra.off"}, {"mesh": "tetra.off", "position": [0.3, 0.1, 0.1], "orientation": ['"$q"'], "motion": {"type": "velocity"}}]}' > "$r2/s/q.json"
  "$cli" run "$r2/s/q.json" --contacts "$r2/q-$(echo "$q" | cut -c1-3).jsonl" > /dev/null 2>&1
done
if cmp -s "$r2/q-1, .jsonl" "$r2/q-1e2.jsonl" && grep -q '"tri_a"' "$r2/q-1, .jsonl"; then passes=$((passes + 1)); else
  echo "FAIL huge-quaternion: [1e200, 0, 0, 1e200] did not give [1, 0, 0, 1]'s contacts"; failures=$((failures + 1)); fi
# Refinement that cannot fit: refused before allocating.
write_grid_off "$r2/grid.off"
check refine-too-big 2 "$cli" refine "$r2/grid.off" "$r2/grid7.off" --levels 7
contains refine-too-big "of memory available"
[ -e "$r2/grid7.off" ] && { echo "FAIL refine-too-big: wrote an output"; failures=$((failures + 1)); }
if [ "$asan" = 0 ]; then
  check out-of-memory 2 bash -c "ulimit -v 400000; exec \"\$0\" query \"\$1\" \"\$1\" --kind proximity --tolerance 5" "$cli" "$r2/grid.off"
  contains out-of-memory "grid.off: out of memory while running the query"
fi
# Outputs: checked before the work, never two in one file, never over an input, never half-written.
check out-same-file 2 "$cli" run "$data/scenes/tetras.json" --json "$r2/o.json" --contacts "$r2/o.json"
contains out-same-file "names the same file as --json"
check out-over-input 2 "$cli" run "$r2/s/q.json" --contacts "$r2/s/q.json"
contains out-over-input "would overwrite the input scene file"
check out-over-mesh 2 "$cli" run "$r2/s/q.json" --json "$r2/s/tetra.off"
check out-no-folder 2 "$cli" run "$data/scenes/tetras.json" --json /nonexistent/r.json
contains out-no-folder "no folder /nonexistent"
contains out-no-folder "/nonexistent/r.json"
# The reason an output cannot be written is the system's: a "folder" that is a file; a name of 251
# bytes is written (its temporary file's name is cut to fit), one of 300 is too long, before any work.
touch "$r2/plain"
check out-folder-is-file 2 "$cli" run "$data/scenes/tetras.json" --contacts "$r2/plain/c.jsonl"
contains out-folder-is-file "$r2/plain/c.jsonl: cannot be written (--contacts): $r2/plain is not a folder"
long=$(printf 'x%.0s' $(seq 245))
check out-long-name 0 "$cli" run "$data/scenes/tetras.json" --contacts "$r2/$long.jsonl"
[ -s "$r2/$long.jsonl" ] && passes=$((passes + 1)) || { echo "FAIL out-long-name: not written"; failures=$((failures + 1)); }
rm -f "$r2/$long.jsonl"
# Two long names alike up to where their temporary names are cut: each output gets its own.
check out-long-names-apart 0 "$cli" run "$data/scenes/tetras.json" --json "$r2/${long}_r.json" --contacts "$r2/${long}_c.json"
if grep -q "\"summary\"" "$r2/${long}_r.json" && ! grep -q "\"summary\"" "$r2/${long}_c.json"; then passes=$((passes + 1)); else
  echo "FAIL out-long-names-apart: the outputs were mixed up"; failures=$((failures + 1)); fi
rm -f "$r2/${long}_r.json" "$r2/${long}_c.json"
check out-name-too-long 2 "$cli" run "$data/scenes/tetras.json" --contacts "$r2/$long$long.jsonl"
contains out-name-too-long "cannot be written (--contacts): File name too long"
case "$out" in *"step 0"*) echo "FAIL out-name-too-long: the run went on"; failures=$((failures + 1)) ;; esac
if [ -w /dev/full ]; then
  check out-full-contacts 2 "$cli" run "$data/scenes/tetras.json" --contacts /dev/full
  contains out-full-contacts "/dev/full: could not be written"
  check out-full-refine 2 "$cli" refine "$data/tetra.off" /dev/full --levels 6
  check out-full-stdout 2 bash -c 'exec "$0" query "$1" "$1" --json > /dev/full' "$cli" "$data/tetra.off"
  contains out-full-stdout "standard output: could not be written"
fi
check refine-over-input 2 "$cli" refine "$r2/s/tetra.off" "$r2/s/tetra.off"
contains refine-over-input "would overwrite the input IN"
# Two runs writing one report at once: each write is whole (temporary file, then rename).
"$cli" run "$data/scenes/tetras.json" --json "$r2/same.json" > /dev/null 2>&1 &
"$cli" run "$data/scenes/tetras.json" --json "$r2/same.json" > /dev/null 2>&1
wait
python3 -c "import json, sys; json.load(open(sys.argv[1]))" "$r2/same.json" && passes=$((passes + 1)) || {
  echo "FAIL out-concurrent: invalid JSON"; failures=$((failures + 1)); }
ls "$r2"/.same.json.* > /dev/null 2>&1 && { echo "FAIL out-concurrent: temporary file left"; failures=$((failures + 1)); }
# bench checks its scenes before it creates a folder.
check bench-bad-scene-no-folder 2 "$bench" "$r2/s/tol.json" --out "$r2/benchdir"
[ -e "$r2/benchdir" ] && { echo "FAIL bench-bad-scene-no-folder: created $r2/benchdir"; failures=$((failures + 1)); }
# SIGINT: the step in progress ends, what was measured is written, exit 130.
"$cli" run "$data/scenes/tetras.json" --steps 100000000 --json "$r2/int.json" --contacts "$r2/int.jsonl" > /dev/null 2>&1 &
pid=$!
for _ in $(seq 100); do compgen -G "$r2/.int.jsonl.caliber-$pid-*.tmp" > /dev/null && break; sleep 0.1; done
sleep 0.5
kill -INT "$pid"
wait "$pid"
rc=$?
if [ "$rc" = 130 ] && python3 - "$r2/int.json" "$r2/int.jsonl" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["interrupted"] is True and 0 < r["summary"]["steps"] < 100000000, r["summary"]
assert len(open(sys.argv[2]).read().splitlines()) == r["summary"]["steps"]
PY
then passes=$((passes + 1)); else echo "FAIL sigint: exit $rc"; failures=$((failures + 1)); fi
rm -rf "$r2"

# Special files, empty values and misnamed outputs.
h=$(mktemp -d)
mkfifo "$h/fifo.json"
check scene-fifo 2 timeout 10 "$cli" run "$h/fifo.json"
contains scene-fifo "fifo.json: is not a regular file"
check scene-dev-zero 2 timeout 10 "$cli" run /dev/zero
contains scene-dev-zero "/dev/zero: is not a regular file"
check log-fifo 2 timeout 10 "$bench" --from-log "$h/fifo.json" --out "$h/b"
contains log-fifo "is not a regular file"
check empty-output-name 2 "$cli" run "$data/scenes/tetras.json" --json ""
contains empty-output-name "--json: must not be empty"
check empty-number 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --kind distance --tolerance '' --pose-b "2 0 0 1 0 0 0"
contains empty-number "--tolerance: must not be empty"
check refine-not-off 2 "$cli" refine "$data/tetra.off" "$h/r.obj"
contains refine-not-off "OUT: must name an .off file"
[ -e "$h/r.obj" ] && { echo "FAIL refine-not-off: wrote $h/r.obj"; failures=$((failures + 1)); }
check refine-full-stdout 2 sh -c '"$0" refine "$1" "$2" > /dev/full' "$cli" "$data/tetra.off" "$h/r.off"
contains refine-full-stdout "standard output: could not be written"
python3 - "$h" "$data" <<'PY'
import json, os, sys
h, data = sys.argv[1], os.path.abspath(sys.argv[2])
with open(f"{h}/nul.json", "wb") as f:
    f.write(json.dumps({"steps": 1, "objects": [{"mesh": f"{data}/tetra.off"}]}).encode() + b"\0{{{junk\n")
json.dump({"steps": 3, "dt": 0.1, "objects": [{"name": "fixed", "mesh": f"{data}/tetra.off"},
           {"name": "mover", "mesh": f"{data}/tetra.off", "position": [0, 0.1, 0.1],
            "motion": {"type": "velocity", "linear": [1e-36, 0, 0]}}]}, open(f"{h}/tiny.json", "w"))
json.dump({"steps": 3, "dt": 0.1, "query": {"kind": "proximity", "tolerance": 0.05, "max_pairs": 1},
           "objects": [{"name": "fixed", "mesh": f"{data}/tetra.off", "refine": 2},
                       {"name": "mover", "mesh": f"{data}/tetra.off", "refine": 2, "position": [0.2, 0.1, 0.1],
                        "motion": {"type": "velocity", "linear": [-0.1, 0, 0]}}]}, open(f"{h}/cut.json", "w"))
json.dump({"steps": 3, "query": {"kind": 3}, "objects": [{"mesh": f"{data}/tetra.off"}]}, open(f"{h}/kind.json", "w"))
json.dump({"steps": 2, "dt": 1, "objects": [{"name": "fixed", "mesh": f"{data}/tetra.off"},
           {"name": "mover", "mesh": f"{data}/tetra.off", "motion": {"type": "keyframes", "keys": [
               {"time": -1.7e308, "position": [-1000, 0, 0]}, {"time": 1.7e308, "position": [1000, 0, 0]}]}}]},
          open(f"{h}/keyspan.json", "w"))
PY
check scene-nul 2 "$cli" run "$h/nul.json"
contains scene-nul "holds a NUL byte at offset"
check motion-tiny 2 "$cli" run "$h/tiny.json"
contains motion-tiny "object 'mover' (objects[1].motion) has a translation component below 2^-120"
check motion-tiny-continuous 2 "$cli" run "$h/tiny.json" --continuous
contains motion-tiny-continuous "object 'mover' (objects[1].motion)"
check scene-max-pairs 0 "$cli" run "$h/cut.json"
contains scene-max-pairs "reached max_pairs 1 (the scene's query)"
check scene-kind-once 2 "$cli" run "$h/kind.json"
contains scene-kind-once "kind.json: 'query.kind': must be a string"
case "$out" in *"kind.json: 'query.kind': "*"kind.json"*) echo "FAIL scene-kind-once: $out"; failures=$((failures + 1)) ;; esac
mkfifo "$h/pipe.off"
printf '{"objects": [{"mesh": "pipe.off"}]}' > "$h/pipe.json"
check scene-mesh-fifo 2 timeout 10 "$cli" run "$h/pipe.json"
contains scene-mesh-fifo "'objects[0].mesh': not a regular mesh file"
check query-empty-path 2 "$cli" query "" "$data/tetra.off"
contains query-empty-path "mesh path: is empty"
check motion-tiny-export 2 "$cli" run "$h/tiny.json" --export "$h/e5" --export-steps 0 --json "$h/r5.json"
[ -e "$h/e5" ] || [ -e "$h/r5.json" ] && { echo "FAIL motion-tiny-export: a failed run left $(ls "$h")"; failures=$((failures + 1)); }
check export-steps-twice 2 "$cli" run "$data/scenes/tetras.json" --export "$h/e6" --export-steps 0,0
contains export-steps-twice "--export-steps: step 0 is listed twice"
check bench-log-folder 2 "$bench" "$data/scenes/tetras.json" --out "$h/b1" --log "$h" --steps 2
contains bench-log-folder "--log: '$h' is a folder, not a log file"
[ -e "$h/b1" ] && { echo "FAIL bench-log-folder: created $h/b1"; failures=$((failures + 1)); }
check bench-scene-twice 2 "$bench" "$data/scenes/tetras.json" "$data/scenes/tetras.json" --out "$h/b2" --steps 2
contains bench-scene-twice "scene 'tetras' is given twice"
check query-threads-range 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --threads -5
check sweep-tolerance-nan 2 "$cli" run "$data/scenes/tetras.json" --sweep-tolerance nan
check export-bad-threads-no-folder 2 "$cli" run "$data/scenes/tetras.json" --export "$h/e4" --threads 99999
[ -e "$h/e4" ] && { echo "FAIL export-bad-threads-no-folder: created $h/e4"; failures=$((failures + 1)); }
# Whole numbers in decimal (C's 010 was 8), no number that rounds to 0 from a non-zero value, no
# keys too far apart to interpolate between (the mover stayed at the first key).
check steps-leading-zero 0 "$cli" run "$data/scenes/tetras.json" --steps 010
contains steps-leading-zero "summary over 10 steps"
check steps-hex 2 "$cli" run "$data/scenes/tetras.json" --steps 0x10
contains steps-hex "--steps: must be a whole number in decimal digits, not '0x10'"
check tolerance-underflow 2 "$cli" query "$data/tetra.off" "$data/tetra.off" --kind proximity --tolerance 1e-400
contains tolerance-underflow "--tolerance: is too small for a double (it would be read as 0): '1e-400'"
check keys-too-far-apart 2 "$cli" run "$h/keyspan.json"
contains keys-too-far-apart "'objects[1].motion.keys[1].time': is too far from the key before it"
rm -rf "$h"

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
