#!/usr/bin/env bash
# Installs what is missing, builds, extracts CGAL's meshes, and runs the main job: the paper's
# front_car scene (23 parts, 150 steps) with its summary and Table 1 characteristics.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
"$root/scripts/fetch_meshes.sh"
echo
"$root/build/caliber" run "$root/scenes/front_car.json"
