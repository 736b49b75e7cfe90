# The helpers of the CLI tests: check and contains count passes and failures (sourced).
failures=0
passes=0
check() {  # check NAME EXPECTED_RC COMMAND... ; stderr/stdout kept in $out
  local name="$1" want="$2"
  shift 2
  out=$("$@" 2>&1)
  local rc=$?
  if [ "$rc" -ne "$want" ]; then
    echo "FAIL $name: exit $rc, wanted $want; output: $out"
    failures=$((failures + 1))
    return 1
  fi
  passes=$((passes + 1))
  return 0
}
contains() {  # contains NAME TEXT
  if ! grep -qF -- "$2" <<<"$out"; then
    echo "FAIL $1: output lacks '$2': $out"
    failures=$((failures + 1))
  else
    passes=$((passes + 1))
  fi
}

# write_grid_off FILE: a flat grid of 200 x 200 squares (80,000 triangles) as an OFF file.
write_grid_off() {
  python3 - "$1" <<'PY'
import sys
n = 200
with open(sys.argv[1], "w") as f:
    f.write(f"OFF\n{(n + 1) ** 2} {2 * n * n} 0\n")
    for i in range(n + 1):
        for j in range(n + 1):
            f.write(f"{i} {j} 0\n")
    for i in range(n):
        for j in range(n):
            a, b, c, d = i * (n + 1) + j, i * (n + 1) + j + 1, (i + 1) * (n + 1) + j, (i + 1) * (n + 1) + j + 1
            f.write(f"3 {a} {b} {d}\n3 {a} {d} {c}\n")
PY
}
