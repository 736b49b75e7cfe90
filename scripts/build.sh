#!/usr/bin/env bash
# Configures and builds caliber (Release) into build/: the library, build/caliber, the tests and
# the benchmarks, the Python module and the viewer. Extra arguments go to cmake's configure step.
# Then makes the Python module importable by Debian's python3 without PYTHONPATH, as `pip install
# -e` would: a caliber.pth naming build/python in the user's site-packages (the last build run wins;
# CALIBER_NO_PTH=1 skips it).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$root/build" -j "${JOBS:-2}"
if [ -z "${CALIBER_NO_PTH:-}" ] && ls "$root"/build/python/caliber*.so > /dev/null 2>&1 && [ -x /usr/bin/python3 ]; then
  site="$(/usr/bin/python3 -m site --user-site)"
  mkdir -p "$site"
  echo "$root/build/python" > "$site/caliber.pth"
  echo "build: python3 imports caliber from $root/build/python ($site/caliber.pth)"
fi
