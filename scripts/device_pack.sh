#!/usr/bin/env bash
# Packs what another machine needs to run caliber without our Debian packages (for example a
# 16-core Intel Xeon machine running Ubuntu 24.04, whose glibc is newer than Debian 12's), into
# .devicepack/ (git-ignored): the Release binary, the benchmarks bench_batch, bench_broad_phase and
# bench_sweep_many,
# every shared library they load except the C library's own, the four scenes and the meshes they
# read, the meshes of the many-part scenes, of bench_batch and of bench_sweep_many, and run.sh, the one command to run
# there:
#
#   scripts/device_pack.sh            # here: build (Release) and pack; prints the pack's size
#   bash .devicepack/run.sh ARGS...   # there (.devicepack copied to the other machine): runs
#                                     # `caliber ARGS...` with the packed libraries; results go
#                                     # under $OUT when ARGS name $OUT
#   bash .devicepack/run.sh bench_batch ARGS...        # the packed benchmarks, likewise
#   bash .devicepack/run.sh bench_broad_phase ARGS...
#   bash .devicepack/run.sh bench_sweep_many ARGS...
#
# For example, a bench that cannot lose its results when a time limit (here 10 minutes) cuts it:
#
#   bash .devicepack/run.sh bench --threads 1,4,8,16 --repeat 5 --budget-s 540 --no-figures \
#        --no-fcl --out "$OUT/bench"
#
# The pack is checked before it is declared ready: its binary must start with only the packed
# libraries and the C library (a clean environment, LD_LIBRARY_PATH set to the pack alone), and
# the whole pack must stay under 64 MiB, small enough to copy to a remote machine.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
pack="$root/.devicepack"
limit_mib=64

"$root/scripts/build.sh" >/dev/null
"$root/scripts/fetch_meshes.sh" >/dev/null

rm -rf "$pack"
mkdir -p "$pack/bin" "$pack/lib" "$pack/scenes" "$pack/data/meshes"
binaries=(caliber caliber-bench bench_batch bench_broad_phase bench_sweep_many)
for binary in "${binaries[@]}"; do
  cp "$root/build/$binary" "$pack/bin/"
  strip "$pack/bin/$binary"
done
# A baseline to compare with, interleaved (scripts/device_compare.sh): BASELINE_BUILD names the
# build folder of an older commit (git worktree add /tmp/old COMMIT; build caliber_cli, caliber_bench_program, bench_batch
# and bench_sweep_many there); its binaries go to .devicepack/old/ (same libraries).
if [ -n "${BASELINE_BUILD:-}" ]; then
  mkdir -p "$pack/old"
  for binary in caliber caliber-bench bench_batch bench_sweep_many; do
    [ -f "$BASELINE_BUILD/$binary" ] || continue  # an older build has no caliber-bench
    cp "$BASELINE_BUILD/$binary" "$pack/old/" && strip "$pack/old/$binary"
  done
  cp "$root/scripts/device_compare.sh" "$pack/"
fi

# Every library the binary loads, but glibc's own (the C library, its companions, the dynamic
# loader): those come from the other machine's system (glibc is backward compatible, not forward).
is_glibc() {
  case "$(basename "$1")" in
    libc.so.*|libm.so.*|libmvec.so.*|libpthread.so.*|libdl.so.*|librt.so.*|libresolv.so.*|libutil.so.*|libanl.so.*|\
    libnsl.so.*|ld-linux*) return 0 ;;
    *) return 1 ;;
  esac
}
for binary in "${binaries[@]}"; do
  ldd "$root/build/$binary" | awk '/=> \// {print $3}' | while read -r lib; do
    is_glibc "$lib" || cp -L "$lib" "$pack/lib/"
  done
done
# oneTBB opens its allocator at run time when present: the same one as here.
tbb="$(ldd "$root/build/caliber" | awk '/libtbb\.so/ {print $3}')"
for extra in "$(dirname "$tbb")"/libtbbmalloc.so.2 "$(dirname "$tbb")"/libtbbmalloc_proxy.so.2; do
  [ -f "$extra" ] && cp -L "$extra" "$pack/lib/"
done
strip --strip-unneeded "$pack"/lib/*.so* 2>/dev/null || true

# The scenes keep their relative mesh paths (../data/meshes/..., meshes/...).
cp "$root"/scenes/*.json "$pack/scenes/"
cp -r "$root/scenes/meshes" "$pack/scenes/"
python3 - "$root/scenes" <<'PY' | while read -r mesh; do cp "$root/scenes/$mesh" "$pack/scenes/$mesh"; done
import json, pathlib, sys
for scene in sorted(pathlib.Path(sys.argv[1]).glob("*.json")):
    for obj in json.loads(scene.read_text())["objects"]:
        if obj["mesh"].startswith("../data/"):
            print(obj["mesh"])
PY
# The many-part scenes' mesh (there, `python3 scenes/generate.py --grid N --out-dir
# .devicepack/data/scenes --mesh .devicepack/data/meshes/eight.off` writes the scenes beside it)
# bench_batch's two and bench_sweep_many's blade (they read data/meshes from the pack's folder).
for mesh in eight.off bunny00.off turbine.off blade.off; do cp "$root/data/meshes/$mesh" "$pack/data/meshes/"; done

cat > "$pack/run.sh" <<'RUN'
#!/usr/bin/env bash
# Runs the packed caliber with the packed libraries (see scripts/device_pack.sh). Scenes are under
# .devicepack/scenes; `bench` without scenes runs those four. `run.sh bench_batch ...`,
# `run.sh bench_broad_phase ...` and `run.sh bench_sweep_many ...` run the packed benchmarks.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
export LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
cd "$here"
case "${1:-}" in
  bench_batch|bench_broad_phase|bench_sweep_many) binary="$1"; shift; exec "$here/bin/$binary" "$@" ;;
esac
if [ "${1:-}" = bench ]; then
  named=0
  for arg in "$@"; do
    case "$arg" in *.json) named=1 ;; esac
  done
  if [ "$named" = 0 ]; then
    shift
    exec "$here/bin/caliber-bench" scenes/two_large.json scenes/two_small.json scenes/funnel.json scenes/front_car.json "$@"
  fi
  shift
  exec "$here/bin/caliber-bench" "$@"
fi
exec "$here/bin/caliber" "$@"
RUN
chmod +x "$pack/run.sh"

# The check: with the pack's folder first, every library but glibc's must resolve inside the pack
# (ldd would otherwise find this machine's copies and hide a library the other machine lacks).
outside="$(for binary in "${binaries[@]}"; do env -i LD_LIBRARY_PATH="$pack/lib" ldd "$pack/bin/$binary"; done | awk '/=>/ {print $1, $3}' |
  while read -r name path; do
    is_glibc "$name" && continue
    case "$path" in "$pack/lib/"*) ;; *) echo "$name -> $path" ;; esac
  done)"
if [ -n "$outside" ]; then
  echo "device_pack: libraries not taken from the pack:" >&2
  echo "$outside" >&2
  exit 1
fi
env -i PATH=/usr/bin:/bin bash "$pack/run.sh" run scenes/two_small.json --steps 2 --threads 2 --method hybrid >/dev/null 2>&1 ||
  { echo "device_pack: the packed binary does not run a scene with the packed libraries alone" >&2; exit 1; }
size_kib="$(du -sk "$pack" | cut -f1)"
if [ "$size_kib" -gt $((limit_mib * 1024)) ]; then
  echo "device_pack: the pack is $((size_kib / 1024)) MiB, over the ${limit_mib} MiB limit" >&2
  exit 1
fi
echo "device_pack: $pack ready ($((size_kib / 1024)) MiB; commit $(git -C "$root" rev-parse --short HEAD)$(git -C "$root" diff --quiet || echo '+dirty'))"
