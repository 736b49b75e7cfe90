#!/usr/bin/env bash
# Sanitizer builds of the tests, through the CMake presets of the same names (CMakePresets.json):
#   scripts/sanitize.sh address   AddressSanitizer + UndefinedBehaviorSanitizer, every test
#   scripts/sanitize.sh thread    ThreadSanitizer (std::thread executor), the parallel tests
# Builds into build-<kind>/ and runs ctest there; exits non-zero on any report.
set -euo pipefail
kind="${1:-thread}"
case "$kind" in
  address | thread) ;;
  *) echo "usage: $0 address|thread" >&2; exit 2 ;;
esac
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/fetch_meshes.sh" >/dev/null
cd "$root"
cmake --preset "$kind" >/dev/null
cmake --build --preset "$kind" -j "${JOBS:-2}"
ctest --preset "$kind" -j "${JOBS:-2}"
