#!/usr/bin/env bash
# Installs what is missing, builds, extracts the test meshes, and runs every test (ctest).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
"$root/scripts/fetch_meshes.sh"
cd "$root/build"
ctest --output-on-failure -j "${JOBS:-2}"
