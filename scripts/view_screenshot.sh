#!/usr/bin/env bash
# Regenerates docs/images/viewer_front_car.png: the viewer page of the paper's front_car scene
# (hybrid, this machine's threads) in headless chromium at the step with the most contacts, after
# the same checks as the viewer's test. Needs the build and the meshes (scripts/test.sh).
#   scripts/view_screenshot.sh [STEP]      default: the step with the most contacts
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
"$root/build/caliber" run "$root/scenes/front_car.json" --contacts "$tmp/contacts.jsonl" > /dev/null 2>&1
step="${1:-$(python3 -c 'import json,sys; c=[len(json.loads(l)["contacts"]) for l in open(sys.argv[1])]; print(c.index(max(c)))' "$tmp/contacts.jsonl")}"
"$root/build/caliber" view "$root/scenes/front_car.json" --method hybrid --out "$tmp/front_car.html" 2> /dev/null
mkdir -p "$root/docs/images"
node "$root/viewer/test/view_test.mjs" "$tmp/front_car.html" "$tmp/contacts.jsonl" --screenshot "$root/docs/images/viewer_front_car.png" --step "$step" |
  grep -v "after .* ArrowRight"
