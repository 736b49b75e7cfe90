#!/usr/bin/env bash
# Installs what is missing, builds, extracts CGAL's meshes, and runs the main job: for now an exact
# interference and a contact query between two rotated, overlapping armadillos (52k triangles each).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
"$root/scripts/fetch_meshes.sh"
mesh="$root/data/meshes/armadillo.off"
pose="7.3 -3.0 6.6 0.9659258 0.2312 0.0 0.1156"  # 30 degrees about (2, 0, 1), shifted
echo
"$root/build/caliber" query "$mesh" "$mesh" --pose-b "$pose" --kind interference --show 5
echo
"$root/build/caliber" query "$mesh" "$mesh" --pose-b "$pose" --kind contact --tolerance 0.5 --angle 30 --show 5
