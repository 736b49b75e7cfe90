#!/usr/bin/env bash
# Configures and builds caliber (Release) into build/: the library, build/caliber, the tests and
# the benchmarks. Extra arguments go to cmake's configure step.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$root/build" -j "${JOBS:-2}"
