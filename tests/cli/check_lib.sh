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
