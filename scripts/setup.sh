#!/usr/bin/env bash
# Installs everything caliber needs from Debian's packages (Debian 12). Idempotent: installs only
# what is missing, after an apt-get update. Run as root (or with sudo available).
set -euo pipefail
packages=(
  build-essential cmake pkg-config python3
  libeigen3-dev libtbb-dev libassimp-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libfcl-dev      # benchmarks only: the peer comparison against FCL
  libcgal-demo    # CGAL's mesh collection, extracted by scripts/fetch_meshes.sh
  clang libclang-rt-14-dev  # scripts/fuzz.sh: libFuzzer (Debian 12 ships clang 14)
  python3-matplotlib        # caliber bench: figures (scripts/plot_bench.py)
  python3-dev python3-pybind11 python3-numpy python3-pytest  # the Python module and its tests
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
echo "setup: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
