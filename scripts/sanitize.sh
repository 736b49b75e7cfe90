#!/usr/bin/env bash
# Sanitizer builds of the tests: `scripts/sanitize.sh thread` (ThreadSanitizer, the parallel tests)
# or `scripts/sanitize.sh address` (AddressSanitizer + UndefinedBehaviorSanitizer, every test).
# Builds into build-<kind>/ and runs ctest there; exits non-zero on any report.
set -euo pipefail
kind="${1:-thread}"
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/fetch_meshes.sh" >/dev/null
cmake -S "$root" -B "$root/build-$kind" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCALIBER_SANITIZE="$kind" -DCALIBER_BUILD_BENCH=OFF >/dev/null
cmake --build "$root/build-$kind" -j "${JOBS:-2}" --target all
cd "$root/build-$kind"
if [ "$kind" = thread ]; then
  export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1"
  ctest --output-on-failure -j "${JOBS:-2}" -R "Engine|World|QueryOracle|Executor|Concurrency"
else
  export ASAN_OPTIONS="detect_leaks=1 halt_on_error=1"
  export LSAN_OPTIONS="suppressions=$root/tests/sanitizers/lsan.supp"
  export UBSAN_OPTIONS="halt_on_error=1 print_stacktrace=1"
  ctest --output-on-failure -j "${JOBS:-2}"
fi
