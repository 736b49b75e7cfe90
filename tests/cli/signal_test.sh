#!/usr/bin/env bash
# SIGTERM (kill, timeout, systemd, batch schedulers) and SIGINT (Ctrl-C) during the long commands:
# run, run --continuous, view, bench and refine stop after the step in progress, write what they
# measured ("interrupted": true in a JSON report or page) and exit 128 + the signal's number (143,
# 130); no temporary file (.NAME.caliber-PID-N.tmp) is ever left. And a report that cannot be put in
# place at the end names the system's reason.
# usage: signal_test.sh CALIBER TEST_DATA_DIR
set -u
cli="$1"
bench="$(dirname "$cli")/caliber-bench"  # the benchmark program, built beside caliber
data="$(cd "$2" && pwd)"
source "$(dirname "$0")/check_lib.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene="$data/scenes/tetras.json"

# finish PID: waits for the process, at most 60 s (then it is killed: a command that went on after
# the signal); $rc is its exit status.
finish() {
  for _ in $(seq 600); do kill -0 "$1" 2> /dev/null || break; sleep 0.1; done
  kill -0 "$1" 2> /dev/null && kill -KILL "$1"
  wait "$1"
  rc=$?
}
# stop NAME SIGNAL WATCHED COMMAND...: runs COMMAND (output in $tmp/NAME.out), waits until its
# output WATCHED (a path), or that output's temporary file, holds data, sends SIGNAL; $rc is its
# exit status.
stop() {
  local name="$1" signal="$2" watched="$3"
  shift 3
  "$@" > "$tmp/$name.out" 2>&1 &
  local pid=$!
  local temp
  temp="$(dirname "$watched")/.$(basename "$watched").caliber-$pid-*.tmp"
  for _ in $(seq 200); do compgen -G "$temp" > /dev/null || [ -s "$watched" ] && break; sleep 0.05; done
  sleep 0.3
  kill "-$signal" "$pid"
  finish "$pid"
}
# verdict NAME WANTED_RC FOLDER: the exit status, and no temporary file left in FOLDER.
verdict() {
  local left
  left=$(ls -A "$3" | grep 'caliber-.*\.tmp')
  if [ "$rc" != "$2" ] || [ -n "$left" ]; then
    echo "FAIL $1: exit $rc (wanted $2), temporary files: '$left'; output: $(tail -5 "$tmp/$1.out")"
    failures=$((failures + 1))
    return 1
  fi
  passes=$((passes + 1))
}

# run --json --contacts: the report says interrupted, the contacts hold one line per step done.
for signal in TERM INT; do
  d="$tmp/run-$signal"
  mkdir "$d"
  stop "run-$signal" "$signal" "$d/c.jsonl" "$cli" run "$scene" --steps 100000000 --json "$d/r.json" --contacts "$d/c.jsonl"
  want=$([ "$signal" = TERM ] && echo 143 || echo 130)
  verdict "run-$signal" "$want" "$d" && python3 - "$d/r.json" "$d/c.jsonl" <<'PY' || { echo "FAIL run-$signal-report"; failures=$((failures + 1)); }
import json, sys
r = json.load(open(sys.argv[1]))
assert r["interrupted"] is True and 0 < r["summary"]["steps"] < 100000000, r["summary"]
assert len(r["steps"]) == r["summary"]["steps"]
assert len(open(sys.argv[2]).read().splitlines()) == r["summary"]["steps"]
PY
  grep -q "interrupted (SIG$signal) after" "$tmp/run-$signal.out" || { echo "FAIL run-$signal-message"; failures=$((failures + 1)); }
done

# run --continuous --json: the intervals swept, then the summary.
d="$tmp/continuous"
mkdir "$d"
stop continuous TERM "$d/k.json" "$cli" run "$scene" --continuous --steps 100000000 --json "$d/k.json"
verdict continuous 143 "$d" && python3 - "$d/k.json" <<'PY' || { echo "FAIL continuous-report"; failures=$((failures + 1)); }
import json, sys
r = json.load(open(sys.argv[1]))
assert r["interrupted"] is True and 0 < r["summary"]["intervals"] == len(r["intervals"]), r["summary"]
PY

# view: the page of the steps done, which says it was interrupted (when this build has the viewer).
if "$cli" view "$scene" --steps 1 --out "$tmp/probe.html" > /dev/null 2>&1; then
  for signal in TERM INT; do
    d="$tmp/view-$signal"
    mkdir "$d"
    stop "view-$signal" "$signal" "$d/v.html" "$cli" view "$scene" --steps 100000000 --out "$d/v.html"
    want=$([ "$signal" = TERM ] && echo 143 || echo 130)
    verdict "view-$signal" "$want" "$d" && python3 - "$d/v.html" <<'PY' || { echo "FAIL view-$signal-page"; failures=$((failures + 1)); }
import json, re, sys
page = open(sys.argv[1], encoding="utf-8").read()
data = json.loads(re.search(r'<script id="caliber-data" type="application/json">(.*?)</script>', page, re.S).group(1))
assert data["interrupted"] is True and 0 < len(data["steps"]) < 100000000, len(data["steps"])
assert page.rstrip().endswith("</html>")
PY
  done
fi

# bench: results.json and report.md of the runs done, the log's last record says why it stopped.
d="$tmp/bench"
stop bench TERM "$d/runs.jsonl" "$bench" "$scene" --steps 2000000 --repeat 1 --threads 1 --no-fcl --no-ceiling --out "$d"
if verdict bench 143 "$d"; then
  python3 - "$d" <<'PY' || { echo "FAIL bench-results"; failures=$((failures + 1)); }
import json, os, sys
r = json.load(open(sys.argv[1] + "/results.json"))
assert r["interrupted"] is True and r["stopped"]["reason"] == "interrupted" and r["stopped"]["signal"] == "SIGTERM", r
last = json.loads(open(sys.argv[1] + "/runs.jsonl").read().splitlines()[-1])
assert last["kind"] == "stopped" and last["reason"] == "interrupted", last
assert "**interrupted** (SIGTERM)" in open(sys.argv[1] + "/report.md").read()
# No figures: they are left to --from-log.
assert r["figures_note"].startswith("Figures not drawn: the bench was interrupted (SIGTERM)"), r["figures_note"]
assert not [f for f in os.listdir(sys.argv[1]) if f.endswith(".svg")], os.listdir(sys.argv[1])
PY
fi

# refine: one step, nothing partial to keep: no output and no temporary file. Three levels (5M
# triangles) run long enough to be stopped as they work and end well within finish's 60 s under
# AddressSanitizer, where four levels (20M triangles, 700 MB of OFF) took 60 s alone.
write_grid_off "$tmp/grid.off"
d="$tmp/refine"
mkdir "$d"
"$cli" refine "$tmp/grid.off" "$d/fine.off" --levels 3 > "$tmp/refine.out" 2>&1 &
pid=$!
for _ in $(seq 200); do compgen -G "$d/.fine.off.caliber-$pid-*.tmp" > /dev/null && break; sleep 0.01; done
kill -TERM "$pid"
finish "$pid"
verdict refine 143 "$d" && [ ! -e "$d/fine.off" ] && passes=$((passes + 1)) || {
  echo "FAIL refine-no-output: $(ls -A "$d")"; failures=$((failures + 1)); }

# A report that cannot be put in place (its name became a folder during the run) names the reason
# (the reason was lost: "Success"), and leaves no temporary file.
d="$tmp/rename"
mkdir "$d"
"$cli" run "$scene" --steps 100000000 --json "$d/r.json" --contacts "$d/c.jsonl" > "$tmp/rename.out" 2>&1 &
pid=$!
for _ in $(seq 200); do compgen -G "$d/.c.jsonl.caliber-$pid-*.tmp" > /dev/null && break; sleep 0.05; done
mkdir "$d/c.jsonl"
kill -INT "$pid"
finish "$pid"
verdict rename 2 "$d" && grep -q "c.jsonl: could not be put in place: Is a directory" "$tmp/rename.out" &&
  passes=$((passes + 1)) || { echo "FAIL rename-reason: $(cat "$tmp/rename.out" | tail -1)"; failures=$((failures + 1)); }

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
