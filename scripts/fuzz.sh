#!/usr/bin/env bash
# Fuzzes the mesh loaders, the OBJ reader, the scene parser and the pose parser with libFuzzer
# (clang, from Debian's clang and libclang-rt-dev packages; scripts/setup.sh installs them), and
# the Python module's unpickler with tests/fuzz/unpickle_fuzz.py (the module of build/, from
# scripts/build.sh).
#   scripts/fuzz.sh [SECONDS] [TARGET...]      default: 60 seconds each, targets mesh_loader
#                                              obj_reader scene pose unpickle
# Builds into build-fuzz/ (ASan + UBSan + coverage), starts from the committed seeds in
# tests/fuzz/corpus/<target>/ and keeps what it learns in build-fuzz/corpus/<target>/ (not committed).
# A finding (crash, sanitizer report, non-caliber exception, timeout, out of memory) is written to
# build-fuzz/findings/<target>/ and the script exits non-zero. Fix it, then copy the input into
# tests/fuzz/regressions/<target>/: the <target>_replay tests run it in every build from then on.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-60}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(mesh_loader obj_reader scene pose unpickle)
command -v clang++ >/dev/null || { echo "fuzz: clang++ not found; run scripts/setup.sh" >&2; exit 2; }

native=()
for t in "${targets[@]}"; do [ "$t" = unpickle ] || native+=("$t"); done
(cd "$root" && cmake --preset fuzz >/dev/null)  # CMakePresets.json: clang, CALIBER_FUZZ=ON, build-fuzz/
[ ${#native[@]} -eq 0 ] || cmake --build "$root/build-fuzz" -j "${JOBS:-2}" --target "${native[@]/%/_fuzz}"

export ASAN_OPTIONS="detect_leaks=1"
export LSAN_OPTIONS="suppressions=$root/tests/sanitizers/lsan.supp"
export UBSAN_OPTIONS="halt_on_error=1 print_stacktrace=1"
status=0
for t in "${targets[@]}"; do
  corpus="$root/build-fuzz/corpus/$t"
  findings="$root/build-fuzz/findings/$t"
  mkdir -p "$corpus" "$findings"
  echo "fuzz: $t for ${seconds}s"
  if [ "$t" = unpickle ]; then
    ls "$root"/build/python/caliber*.so >/dev/null 2>&1 || { echo "fuzz: no build/python module; run scripts/build.sh" >&2; exit 2; }
    PYTHONPATH="$root/build/python" /usr/bin/python3 "$root/tests/fuzz/unpickle_fuzz.py" --seconds "$seconds" \
      --findings "$findings" || status=1
    continue
  fi
  if ! "$root/build-fuzz/tests/fuzz/${t}_fuzz" "$corpus" "$root/tests/fuzz/corpus/$t" -max_total_time="$seconds" \
      -timeout=10 -rss_limit_mb=4096 -artifact_prefix="$findings/" -print_final_stats=1 2>"$root/build-fuzz/$t.log"; then
    echo "fuzz: $t FOUND something; see build-fuzz/$t.log and $findings/" >&2
    tail -n 40 "$root/build-fuzz/$t.log" >&2
    status=1
  else
    grep -E "^stat::number_of_executed_units|^Done" "$root/build-fuzz/$t.log" | tr '\n' ' '
    echo
  fi
done
exit $status
