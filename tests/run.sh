#!/bin/sh
# tests/run.sh BUILD — run every test program under BUILD/tests and add up the results.
# Each test is a cmocka program (its own summary lines are kept in the log); the last line
# printed is the plain total "N passed, N failed" that CI reads.
# A program that exits 77 is a skip (counted, with its reason shown).
set -u
build=${1:-build}
export TUBE74="${TUBE74:-./tube74}"
pass=0; fail=0; skip=0
for t in "$build"/tests/test_*; do
  [ -x "$t" ] || continue
  name=$(basename "$t")
  log="$build/tests/$name.log"
  "$t" >"$log" 2>&1
  rc=$?
  p=$(sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' "$log" | tail -n 1)
  f=$(sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' "$log" | tail -n 1)
  p=${p:-0}; f=${f:-0}
  if [ $rc -eq 77 ]; then
    skip=$((skip + 1)); echo "SKIP $name: $(tail -n 1 "$log")"
    continue
  fi
  if [ $rc -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi
  pass=$((pass + p)); fail=$((fail + f))
  if [ $rc -eq 0 ]; then echo "ok   $name ($p)"; else echo "FAIL $name (exit status $rc)"; sed 's/^/     /' "$log" | tail -n 40; fi
done
echo "$pass passed, $fail failed, $skip skipped"
[ $fail -eq 0 ]
