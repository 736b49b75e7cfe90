#!/usr/bin/env bash
# Checks caliber as a package used from outside its tree, as a consumer meets it:
#   - installs the Release build (static library) into a temporary prefix, builds examples/ against
#     it with find_package, runs each example (query_pair's counts against the CLI's; the oneTBB
#     and OpenMP hosts check themselves that caliber started no thread and got the same contacts);
#   - builds query_pair with `pkg-config --cflags --libs --static caliber` alone, from that prefix
#     moved elsewhere (caliber.pc is relocatable);
#   - builds the examples with -ffast-math (caliber's floating-point flags are its own: nothing
#     leaks into the consumer, and the answers do not change);
#   - builds the library shared (-DBUILD_SHARED_LIBS=ON: versioned, internal symbols hidden),
#     installs it, checks the exported symbols, and does the same with `pkg-config --cflags --libs`.
# Called by scripts/test.sh.
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

check_counts() {  # TAG OUTPUT: query_pair's output against the CLI's counts
  [ "$want_i" -gt 0 ] && [ "$want_c" -gt 0 ] || fail "the test pose finds nothing: pick another"
  grep -qx "interference: $want_i pairs" <<<"$2" || fail "$1: interference differs from the CLI's $want_i: $2"
  grep -qx "contact: $want_c contacts" <<<"$2" || fail "$1: contacts differ from the CLI's $want_c: $2"
}

consume() {  # PREFIX TAG [CXXFLAGS]: configures, builds and runs the examples against an installed caliber
  cmake -S "$root/examples" -B "$work/examples-$2" -DCMAKE_PREFIX_PATH="$1" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_CXX_FLAGS="${3:-}" >/dev/null || fail "$2: the examples do not configure against $1"
  cmake --build "$work/examples-$2" -j "${JOBS:-2}" >/dev/null || fail "$2: the examples do not build"
  local out
  out="$("$work/examples-$2/query_pair" "$a" "$b" "$pose" 0.3)" || fail "$2: query_pair failed"
  check_counts "$2" "$out"
  "$work/examples-$2/moving_pair" "$a" "$a" >/dev/null || fail "$2: moving_pair failed"
  out="$("$work/examples-$2/pose_batch" "$a" "$b")" || fail "$2: pose_batch failed: $out"
  out="$("$work/examples-$2/swept_needle")" || fail "$2: swept_needle failed: $out"
  out="$("$work/examples-$2/engine_in_host_arena")" || fail "$2: engine_in_host_arena failed: $out"
  out="$("$work/examples-$2/openmp_host")" || fail "$2: openmp_host failed: $out"
  out="$("$work/examples-$2/host_thread_pool")" || fail "$2: host_thread_pool failed: $out"
  out="$("$work/examples-$2/host_openmp")" || fail "$2: host_openmp failed: $out"
  echo "check_package: $2: the examples build against the installed package and pass ($want_i pairs, $want_c contacts as the CLI)"
}

pkg_consume() {  # PREFIX TAG PKG-CONFIG-ARGS...: query_pair built by pkg-config's flags alone
  local prefix="$1" tag="$2"
  shift 2
  local flags
  flags="$(PKG_CONFIG_PATH="$(dirname "$(find "$prefix" -name caliber.pc | head -1)")" pkg-config "$@" caliber)" ||
    fail "$tag: pkg-config $* caliber failed"
  # shellcheck disable=SC2086
  g++ -O2 -o "$work/query_pair-$tag" "$root/examples/query_pair.cpp" $flags || fail "$tag: query_pair does not build with pkg-config $*: $flags"
  local out
  out="$(LD_LIBRARY_PATH="$prefix/lib" "$work/query_pair-$tag" "$a" "$b" "$pose" 0.3)" || fail "$tag: query_pair (pkg-config) failed"
  check_counts "$tag" "$out"
  echo "check_package: $tag: pkg-config $* caliber builds query_pair, which agrees with the CLI"
}

cmake --install "$build" --prefix "$work/static" >/dev/null
for f in include/caliber/caliber.h include/caliber/version.h include/caliber/export.h lib/libcaliber.a \
         lib/cmake/caliber/caliberConfig.cmake lib/cmake/caliber/caliberConfigVersion.cmake lib/pkgconfig/caliber.pc \
         share/doc/caliber/LICENSE; do
  [ -e "$work/static/$f" ] || fail "static: $f was not installed"
done
consume "$work/static" static
consume "$work/static" static-fast-math "-ffast-math"
# The prefix moved: caliber.pc finds it from its own place.
mv "$work/static" "$work/static-moved"
pkg_consume "$work/static-moved" static-pkg-config --cflags --libs --static

cmake -S "$root" -B "$work/shared-build" -DCMAKE_BUILD_TYPE=Release -DBUILD_SHARED_LIBS=ON -DCALIBER_BUILD_CLI=OFF \
  -DCALIBER_BUILD_TESTS=OFF -DCALIBER_BUILD_BENCH=OFF >/dev/null
cmake --build "$work/shared-build" -j "${JOBS:-2}" >/dev/null
cmake --install "$work/shared-build" --prefix "$work/shared" >/dev/null
so="$(ls "$work"/shared/lib/libcaliber.so.* | head -1)"
[ -L "$work/shared/lib/libcaliber.so" ] || fail "shared: no libcaliber.so link"
readelf -d "$so" | grep -q "SONAME.*libcaliber.so.1.0" || fail "shared: no versioned SONAME"
nm -DC --defined-only "$so" > "$work/symbols"
internal="$(grep -c ' caliber::\(narrow\|tasks\|schedule\|parallel\|geometry\|mesh_io\|bvh\|util\)::' "$work/symbols" || true)"
[ "$internal" = 0 ] || fail "shared: $internal internal symbols exported"
grep -q ' caliber::query(' "$work/symbols" || fail "shared: caliber::query is not exported"
LD_LIBRARY_PATH="$work/shared/lib" consume "$work/shared" shared
pkg_consume "$work/shared" shared-pkg-config --cflags --libs
