#!/usr/bin/env bash
# Installs what is missing, builds, extracts the test meshes, runs every test (ctest), and checks
# the installed package from a project outside the tree (scripts/check_package.sh).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
# The C++ follows .clang-format (clang-format -i FILE fixes a file).
(cd "$root" && git ls-files 'include/*.h' 'src/*.cpp' 'src/*.h' 'src/*.inc' 'apps/*.cpp' 'apps/*.h' 'bench/*.cpp' 'bench/*.h' \
  'tests/*.cpp' 'tests/*.h' 'python/*.cpp' 'python/*.h' 'examples/*.cpp' | xargs clang-format --dry-run -Werror) ||
  { echo "test: the files above do not follow .clang-format (clang-format -i FILE)" >&2; exit 1; }
echo "test: the C++ follows .clang-format"
"$root/scripts/build.sh"
"$root/scripts/fetch_meshes.sh"
cd "$root/build"
ctest --output-on-failure -j "${JOBS:-2}"
# caliber as a package used from outside its tree: installed static and shared, found by CMake.
"$root/scripts/check_package.sh" "$root/build"
# The Python module as a user meets it after this set-up: no PYTHONPATH, from another folder, and
# the README's example (examples/python/readme_example.py) run as it stands.
(cd / && env -u PYTHONPATH /usr/bin/python3 -c "import caliber, sys; assert caliber.__file__.startswith('$root/build/python'), caliber.__file__")
(cd "$root" && env -u PYTHONPATH /usr/bin/python3 examples/python/readme_example.py > /dev/null)
# Every example shown in README.md and docs/ is its file under examples/, which the package check
# above built (C++) and the line above ran (Python).
python3 "$root/scripts/check_examples.py"
echo "test: python3 imports caliber without PYTHONPATH; the README's Python example runs"
# caliber.distributed on a LocalCluster of 2 worker processes, one of them killed mid-batch.
(cd "$root" && env -u PYTHONPATH /usr/bin/python3 -m pytest -q -p no:cacheprovider python/tests_distributed)
echo "test: caliber.distributed gives query_many's answers on a 2-worker Dask cluster"
