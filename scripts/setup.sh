#!/usr/bin/env bash
# Installs everything caliber needs from Debian's packages (Debian 12). Idempotent: installs only
# what is missing, after an apt-get update. Run as root (or with sudo available).
set -euo pipefail
packages=(
  build-essential cmake pkg-config python3
  libeigen3-dev libtbb-dev libassimp-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libgmp-dev      # tests only: exact rationals, the oracle of the exact predicates' test
  libfcl-dev      # benchmarks only: the peer comparison against FCL
  libembree-dev   # benchmarks only: the narrow phase against Embree's rtcCollide
  libbullet-dev   # benchmarks only: the broad phase against Bullet's dynamic AABB tree
  libcgal-demo    # CGAL's mesh collection, extracted by scripts/fetch_meshes.sh
  clang libclang-rt-14-dev  # scripts/fuzz.sh: libFuzzer (Debian 12 ships clang 14)
  clang-format git          # scripts/test.sh: the C++ layout check (.clang-format)
  python3-dev python3-pybind11 python3-numpy python3-pytest  # the Python module and its tests
  python3-distributed       # caliber.distributed: pose batches over a Dask cluster, and its test
  chromium                  # the viewer's test: the page in a headless browser
)
# The viewer is bundled at build time from npm packages (three.js, esbuild; puppeteer-core for its
# test), installed into viewer/node_modules below: Debian's nodejs and npm unless a node is there.
command -v npm > /dev/null || packages+=(nodejs npm)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
else
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "setup: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The viewer's npm packages, at the versions of viewer/package-lock.json (from the npm registry;
# once, and again when the lock file changes). The build only reads them.
viewer="$(cd "$(dirname "$0")/.." && pwd)/viewer"
if [ ! -f "$viewer/node_modules/.package-lock.json" ] || [ "$viewer/package-lock.json" -nt "$viewer/node_modules/.package-lock.json" ]; then
  echo "setup: installing the viewer's npm packages (three.js, esbuild, puppeteer-core) into viewer/node_modules"
  (cd "$viewer" && PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error)
fi
