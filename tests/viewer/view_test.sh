#!/usr/bin/env bash
# caliber view end to end: the page of a scene (hybrid, 2 threads) opened in headless chromium and
# checked against the contacts `caliber run` (sequential) writes for the same scene.
# usage: view_test.sh CALIBER VIEWER_DIR TEST_DATA_DIR
set -euo pipefail
cli=$1 viewer=$2 data=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene="$data/scenes/view_tetras.json"
"$cli" run "$scene" --method sequential --contacts "$tmp/contacts.jsonl" > /dev/null 2>&1
"$cli" view "$scene" --method hybrid --threads 2 --out "$tmp/view.html" 2> /dev/null
node "$viewer/test/view_test.mjs" "$tmp/view.html" "$tmp/contacts.jsonl"
