#!/usr/bin/env bash
# Checks caliber as a package used from outside its tree: installs the Release build (static
# library) into a temporary prefix, configures examples/consumer against it with find_package, runs
# the consumer and compares its counts with the CLI's; then builds the library shared
# (-DBUILD_SHARED_LIBS=ON: versioned, internal symbols hidden), installs it, checks the exported
# symbols and runs the consumer against it too. Called by scripts/test.sh.
#   scripts/check_package.sh [BUILD_DIR]      default build/
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
a="$root/tests/data/tetra.off"
b="$root/tests/data/quad_fan.off"
pose="0.2 0.2 0.3 0 1 0 0"  # B turned over and pushed into A: pairs of both kinds
fail() { echo "check_package: $*" >&2; exit 1; }

want_i="$("$build/caliber" query "$a" "$b" --pose-b "$pose" --json | python3 -c 'import json,sys; print(len(json.load(sys.stdin)["pairs"]))')"
want_c="$("$build/caliber" query "$a" "$b" --pose-b "$pose" --kind contact --tolerance 0.3 --json | python3 -c 'import json,sys; print(len(json.load(sys.stdin)["pairs"]))')"

consume() {  # PREFIX TAG: configures, builds and runs the consumer against an installed caliber
  cmake -S "$root/examples/consumer" -B "$work/consumer-$2" -DCMAKE_PREFIX_PATH="$1" -DCMAKE_BUILD_TYPE=Release >/dev/null ||
    fail "$2: the consumer does not configure against $1"
  cmake --build "$work/consumer-$2" -j "${JOBS:-2}" >/dev/null || fail "$2: the consumer does not build"
  local out
  out="$("$work/consumer-$2/consumer" "$a" "$b" "$pose" 0.3)" || fail "$2: the consumer failed"
  [ "$want_i" -gt 0 ] && [ "$want_c" -gt 0 ] || fail "the test pose finds nothing: pick another"
  grep -qx "interference: $want_i pairs" <<<"$out" || fail "$2: interference differs from the CLI's $want_i: $out"
  grep -qx "contact: $want_c contacts" <<<"$out" || fail "$2: contacts differ from the CLI's $want_c: $out"
  echo "check_package: $2: the consumer builds against the installed package and agrees with the CLI ($want_i pairs, $want_c contacts)"
}

cmake --install "$build" --prefix "$work/static" >/dev/null
for f in include/caliber/caliber.h include/caliber/version.h include/caliber/export.h lib/libcaliber.a \
         lib/cmake/caliber/caliberConfig.cmake lib/cmake/caliber/caliberConfigVersion.cmake lib/pkgconfig/caliber.pc \
         share/doc/caliber/LICENSE; do
  [ -e "$work/static/$f" ] || fail "static: $f was not installed"
done
consume "$work/static" static

cmake -S "$root" -B "$work/shared-build" -DCMAKE_BUILD_TYPE=Release -DBUILD_SHARED_LIBS=ON -DCALIBER_BUILD_CLI=OFF \
  -DCALIBER_BUILD_TESTS=OFF -DCALIBER_BUILD_BENCH=OFF >/dev/null
cmake --build "$work/shared-build" -j "${JOBS:-2}" >/dev/null
cmake --install "$work/shared-build" --prefix "$work/shared" >/dev/null
so="$(ls "$work"/shared/lib/libcaliber.so.* | head -1)"
[ -L "$work/shared/lib/libcaliber.so" ] || fail "shared: no libcaliber.so link"
readelf -d "$so" | grep -q "SONAME.*libcaliber.so.0.1" || fail "shared: no versioned SONAME"
nm -DC --defined-only "$so" > "$work/symbols"
internal="$(grep -c ' caliber::\(narrow\|tasks\|schedule\|parallel\|geometry\|mesh_io\|bvh\|util\)::' "$work/symbols" || true)"
[ "$internal" = 0 ] || fail "shared: $internal internal symbols exported"
grep -q ' caliber::query(' "$work/symbols" || fail "shared: caliber::query is not exported"
LD_LIBRARY_PATH="$work/shared/lib" consume "$work/shared" shared
