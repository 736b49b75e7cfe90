#!/usr/bin/env bash
# Installs what is missing, builds, extracts the test meshes, runs every test (ctest), and checks
# the installed package from a project outside the tree (scripts/check_package.sh).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
"$root/scripts/fetch_meshes.sh"
cd "$root/build"
ctest --output-on-failure -j "${JOBS:-2}"
# caliber as a package used from outside its tree: installed static and shared, found by CMake.
"$root/scripts/check_package.sh" "$root/build"
