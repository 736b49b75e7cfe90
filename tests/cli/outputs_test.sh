#!/usr/bin/env bash
# End-to-end checks of what the CLI writes for other tools: the JSON schema version and object
# names, `caliber run --export` (PLY files read back and compared with the contacts), and
# `caliber view`'s page and its refusals. The page in a browser: tests/viewer/view_test.sh.
# usage: outputs_test.sh CALIBER TEST_DATA_DIR
set -u
cli="$1"
bench="$(dirname "$cli")/caliber-bench"  # the benchmark program, built beside caliber
data="$(cd "$2" && pwd)"
source "$(dirname "$0")/check_lib.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene="$data/scenes/view_tetras.json"

# JSON: schema version everywhere, object names in the report and in each contact.
check schema-run 0 "$cli" run "$scene" --json "$tmp/report.json" --contacts "$tmp/contacts.jsonl"
check schema-query 0 "$cli" query "$data/tetra.off" "$data/tetra.off" --pose-b "0.2 0 0 1 0 0 0" --json
python3 - "$tmp/report.json" "$tmp/contacts.jsonl" "$out" <<'PY' || { echo "FAIL schema"; failures=$((failures + 1)); }
import json, sys
r = json.load(open(sys.argv[1]))
assert r["schema_version"] == 2  # the run report; the others are at 1
assert [o["name"] for o in r["objects"]] == ["fixed", "mover", "third"] and r["objects"][1]["id"] == 1
names = {o["id"]: o["name"] for o in r["objects"]}
seen = 0
for line in open(sys.argv[2]):
    j = json.loads(line)
    assert j["schema_version"] == 1
    for c in j["contacts"]:
        assert c["name_a"] == names[c["object_a"]] and c["name_b"] == names[c["object_b"]]
        seen += 1
assert seen > 0
assert json.loads(sys.argv[3])["schema_version"] == 1
PY

# --export: the chosen steps' PLY files, read back. Objects: every vertex posed; contacts: the
# points of --contacts exactly, each with a unit-direction segment; BVH: 8 corners per box.
check export 0 "$cli" run "$scene" --export "$tmp/ply" --export-steps 0,8 --bvh-depth 2 --contacts "$tmp/c2.jsonl"
for k in 0 8; do
  for f in objects contacts bvh; do [ -s "$tmp/ply/step${k}_$f.ply" ] || { echo "FAIL export: no step${k}_$f.ply"; failures=$((failures + 1)); }; done
done
[ "$(ls "$tmp/ply" | wc -l)" = 6 ] || { echo "FAIL export: $(ls "$tmp/ply")"; failures=$((failures + 1)); }
python3 - "$tmp/ply" "$tmp/c2.jsonl" <<'PY' || { echo "FAIL export-contents"; failures=$((failures + 1)); }
import json, math, sys
def ply(path):
    lines = open(path).read().splitlines()
    end = lines.index("end_header")
    counts = {l.split()[1]: int(l.split()[2]) for l in lines[:end] if l.startswith("element")}
    body = [l.split() for l in lines[end + 1:]]
    return counts, body
steps = [json.loads(l) for l in open(sys.argv[2])]
for k in (0, 8):
    counts, body = ply(f"{sys.argv[1]}/step{k}_objects.ply")
    assert counts["vertex"] > 0 and counts["face"] > 0 and len(body) == counts["vertex"] + counts["face"]
    faces = body[counts["vertex"]:]
    assert {f[4] for f in faces} == {"0", "1", "2"}, "every object's faces, tagged"
    counts, body = ply(f"{sys.argv[1]}/step{k}_contacts.ply")
    contacts = steps[k]["contacts"]
    assert counts["vertex"] == 2 * len(contacts) and counts["edge"] == len(contacts)
    for i, c in enumerate(contacts):
        p = [float(x) for x in body[2 * i]]
        assert p == c["point_a"], (p, c["point_a"])
        q = [float(x) for x in body[2 * i + 1]]
        d = [b - a for a, b in zip(p, q)]
        n = math.sqrt(sum(x * x for x in d))
        assert all(abs(x / n - m) < 1e-9 for x, m in zip(d, c["normal"]))
        assert body[2 * len(contacts) + i][2:] == [str(c["object_a"]), str(c["object_b"])]
    counts, body = ply(f"{sys.argv[1]}/step{k}_bvh.ply")
    assert counts["vertex"] == 8 * counts["edge"] // 12 and counts["vertex"] == 8 * 3 * 7, counts
assert len(steps[8]["contacts"]) > 0
PY
check export-read-back 0 "$cli" query "$tmp/ply/step8_objects.ply" "$data/tetra.off"
check export-step-out-of-range 2 "$cli" run "$scene" --export "$tmp/bad" --export-steps 12
contains export-step-out-of-range "--export-steps"
check export-bad-depth 2 "$cli" run "$scene" --export "$tmp/bad" --bvh-depth -2
touch "$tmp/file"
check export-into-file 2 "$cli" run "$scene" --export "$tmp/file"
contains export-into-file "needs a folder"

# caliber view: the page (the data, the script, and nothing that ends a script early).
check view 0 "$cli" view "$scene" --out "$tmp/view.html" --steps 3
contains view "3 steps, 3 objects, stealing"  # the default method
grep -q '"schema_version":1' "$tmp/view.html" && passes=$((passes + 1)) || { echo "FAIL view: no schema"; failures=$((failures + 1)); }
sed 's/"name": "third"/"name": "<\/script><b>third"/; s#"\.\./tetra.off"#"'"$data"'/tetra.off"#g' "$scene" > "$tmp/named.json"
check view-script-name 0 "$cli" view "$tmp/named.json" --out "$tmp/named.html" --steps 2
python3 - "$tmp/named.html" <<'PY' || { echo "FAIL view-script-name: the page"; failures=$((failures + 1)); }
import json, re, sys
page = open(sys.argv[1]).read()
assert page.lower().count("</script") == 2, "the data and the script each end once"
data = json.loads(re.search(r'<script id="caliber-data" type="application/json">(.*?)</script>', page, re.S).group(1))
assert data["objects"][2]["name"] == "</script><b>third" and len(data["steps"]) == 2
PY
check view-no-out 2 "$cli" view "$scene"
check view-missing-scene 2 "$cli" view "$tmp/nope.json" --out "$tmp/v.html"
check view-zero-steps 2 "$cli" view "$scene" --out "$tmp/v.html" --steps 0
check view-negative-steps 2 "$cli" view "$scene" --out "$tmp/v.html" --steps -1
check view-over-scene 2 "$cli" view "$scene" --out "$scene"
check view-bad-method 2 "$cli" view "$scene" --out "$tmp/v.html" --method fastest
check view-no-folder 2 "$cli" view "$scene" --out "$tmp/no/such/v.html"

# bench: nothing it writes may be one of its inputs, checked before its folder or log exists (a
# --log naming a mesh emptied the mesh; naming the scene replaced it and exited 0).
mkdir -p "$tmp/b"
cp "$data/tetra.off" "$tmp/b/tetra.off"
printf '{"name": "b", "steps": 1, "objects": [{"name": "a", "mesh": "tetra.off"}, {"name": "c", "mesh": "tetra.off", "position": [0.1, 0, 0]}]}\n' > "$tmp/b/s.json"
cp "$tmp/b/s.json" "$tmp/b/results.json"
before=$(cat "$tmp/b/"* | md5sum)
quick=(--threads 1 --repeat 1 --no-fcl --no-figures --simulate 2)
check bench-log-over-mesh 2 "$bench" "$tmp/b/s.json" --log "$tmp/b/tetra.off" --out "$tmp/b/out1" "${quick[@]}"
contains bench-log-over-mesh "--log: would overwrite the input mesh of object 'a'"
check bench-log-over-scene 2 "$bench" "$tmp/b/s.json" --log "$tmp/b/s.json" --out "$tmp/b/out2" "${quick[@]}"
contains bench-log-over-scene "--log: would overwrite the input scene file"
check bench-out-over-scene 2 "$bench" "$tmp/b/results.json" --out "$tmp/b" "${quick[@]}"
contains bench-out-over-scene "--out's results.json: would overwrite the input scene file"
[ "$(cat "$tmp/b/"* | md5sum)" = "$before" ] || { echo "FAIL bench-inputs: an input changed"; failures=$((failures + 1)); }
[ -e "$tmp/b/out1" ] || [ -e "$tmp/b/out2" ] && { echo "FAIL bench-inputs: a refused bench made its folder"; failures=$((failures + 1)); }
check bench-from-log-over-log 0 "$bench" "$tmp/b/s.json" --out "$tmp/b/out3" "${quick[@]}"
cp "$tmp/b/out3/runs.jsonl" "$tmp/b/out3/report.md"
check bench-from-log-over-log 2 "$bench" --from-log "$tmp/b/out3/report.md"
contains bench-from-log-over-log "--out's report.md: would overwrite the input --from-log"

# Reports are streamed: a million-step run --json keeps its memory (max RSS) under 100 MB; a run
# that fails mid-way leaves no report and no temporary file. (Not under ASan: its shadow memory.)
printf '{"name": "spin", "steps": 10, "dt": 0.01, "query": {"kind": "contact", "tolerance": 0.05}, "objects": [{"name": "fixed", "mesh": "%s"}, {"name": "spinner", "mesh": "%s", "position": [0.2, 0.1, 0.1], "motion": {"type": "velocity", "linear": [0, 0, 0], "angular": [0, 0, 0.5]}}]}\n' \
  "$data/tetra.off" "$data/tetra.off" > "$tmp/spin.json"
if [ -z "${ASAN_OPTIONS:-}" ]; then
  python3 - "$cli" "$tmp/spin.json" <<'PY' && passes=$((passes + 1)) || { echo "FAIL run-json-memory"; failures=$((failures + 1)); }
import resource, subprocess, sys
subprocess.run([sys.argv[1], "run", sys.argv[2], "--steps", "1000000", "--json", "/dev/null", "--contacts", "/dev/null",
                "--simulate-cores", "2"], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
peak_kb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
assert peak_kb < 100 * 1024, f"a million steps took {peak_kb} KB"
PY
fi
mkdir -p "$tmp/fail"
printf '{"name": "away", "steps": 40, "dt": 1, "objects": [{"name": "still", "mesh": "%s"}, {"name": "rocket", "mesh": "%s", "motion": {"type": "velocity", "linear": [1e14, 0, 0]}}]}\n' \
  "$data/tetra.off" "$data/tetra.off" > "$tmp/fail/away.json"
check run-fails-midway 2 "$cli" run "$tmp/fail/away.json" --json "$tmp/fail/r.json" --contacts "$tmp/fail/c.jsonl"
contains run-fails-midway "rocket"
[ "$(ls -A "$tmp/fail")" = "away.json" ] || { echo "FAIL run-fails-midway: left $(ls -A "$tmp/fail")"; failures=$((failures + 1)); }
check view-fails-midway 2 "$cli" view "$tmp/fail/away.json" --out "$tmp/fail/v.html"
[ "$(ls -A "$tmp/fail")" = "away.json" ] || { echo "FAIL view-fails-midway: left $(ls -A "$tmp/fail")"; failures=$((failures + 1)); }

# Paths and names as data: a folder whose name is not UTF-8, object names with a newline and with
# "<!--<script>": every output is written, the names escaped (\xe9 in JSON text, \x0a in a PLY
# comment, \u003c in the page).
odd="$tmp/caf$(printf '\351')"
mkdir -p "$odd"
cp "$data/tetra.off" "$odd/m.off"
printf '{"name": "odd", "steps": 2, "objects": [{"name": "line\\nbreak", "mesh": "m.off"}, {"name": "<!--<script>", "mesh": "m.off", "position": [0.2, 0.1, 0.1], "motion": {"type": "velocity", "linear": [0, 0, 0], "angular": [0, 0, 0.1]}}]}\n' > "$odd/s.json"
check odd-run 0 "$cli" run "$odd/s.json" --json "$odd/r.json" --contacts "$odd/c.jsonl" --export "$odd/ply" --export-steps 0
check odd-view 0 "$cli" view "$odd/s.json" --out "$odd/v.html"
python3 - "$odd" <<'PY' && passes=$((passes + 1)) || { echo "FAIL odd-names"; failures=$((failures + 1)); }
import json, os, re, sys
odd = os.fsencode(sys.argv[1])
r = json.load(open(odd + b"/r.json", encoding="utf-8"))
assert r["file"].endswith("caf\\xe9/s.json"), r["file"]
assert [o["name"] for o in r["objects"]] == ["line\nbreak", "<!--<script>"]
assert r["objects"][0]["mesh"].endswith("caf\\xe9/m.off")
lines = [json.loads(l) for l in open(odd + b"/c.jsonl", encoding="utf-8")]
assert lines[0]["contacts"] and lines[0]["contacts"][0]["name_b"] == "<!--<script>"
header = open(odd + b"/ply/step0_objects.ply", "rb").read().split(b"end_header")[0].decode()
assert "comment object 0 line\\x0abreak\n" in header and all(l.split(" ")[0] in ("ply", "format", "comment", "element", "property", "") for l in header.split("\n")), header
page = open(odd + b"/v.html", encoding="utf-8").read()
data = re.search(r'<script id="caliber-data" type="application/json">(.*?)</script>', page, re.S).group(1)
assert "<" not in data and "\\u003c!--\\u003cscript>" in data
assert [o["name"] for o in json.loads(data)["objects"]] == ["line\nbreak", "<!--<script>"]
PY

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
