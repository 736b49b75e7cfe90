#!/usr/bin/env bash
# Extracts the benchmark and test meshes from Debian's libcgal-demo (CGAL's mesh collection) into
# data/meshes/, which git ignores. Installs libcgal-demo if it is missing. Idempotent.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="$root/data/meshes"
archive=/usr/share/doc/libcgal-dev/data.tar.gz
meshes=(armadillo.off dragknob.off eight.off ChineseDragon-10kv.off bunny00.off refined_elephant.off
        fandisk_large.off turbine.off blade.off rotor_small.off elephant.off mushroom.off)

if [ ! -f "$archive" ]; then
  echo "fetch_meshes: installing libcgal-demo (CGAL's demo data)"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq libcgal-demo >/dev/null
fi
mkdir -p "$out"
missing=()
for m in "${meshes[@]}"; do [ -s "$out/$m" ] || missing+=("data/meshes/$m"); done
if [ ${#missing[@]} -gt 0 ]; then
  tar -xzf "$archive" -C "$out" --strip-components=2 "${missing[@]}"
fi
echo "fetch_meshes: ${#meshes[@]} meshes in $out"
