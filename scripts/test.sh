#!/usr/bin/env bash
# Installs what is missing, builds, extracts the test meshes, runs every test (ctest), and checks
# the installed package from a project outside the tree (scripts/check_package.sh).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
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
python3 - "$root" <<'PY'
import sys
root = sys.argv[1]
readme = open(f"{root}/README.md").read()
example = open(f"{root}/examples/python/readme_example.py").read()
block = "".join("    " + line + "\n" for line in example.splitlines())
assert block in readme, "README.md's Python example differs from examples/python/readme_example.py"
print("test: python3 imports caliber without PYTHONPATH; the README's Python example runs")
PY
