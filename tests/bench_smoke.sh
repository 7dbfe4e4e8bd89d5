#!/usr/bin/env bash
# bench/bench_parallel.sh on a tiny cut (its quick case r4, MUMPS on one and
# two processes): every row of its table has figures, so a change of the
# run's summary line or of its options that the script reads does not go
# unnoticed (tools/check_bench.sh checks all the scripts without running
# them).
#   tests/bench_smoke.sh SOFTPACK SOURCE_DIR
set -uo pipefail
softpack=$1 source=$2
fail() { echo "FAIL: $*"; exit 1; }
out=$(NPS="1 2" SOLVERS=mumps BIN=$softpack bash "$source/bench/bench_parallel.sh" r4 2>&1) ||
  { echo "$out"; fail "bench/bench_parallel.sh r4 failed"; }
echo "$out"
rows=$(grep -c '^| mumps | [12] |' <<< "$out")
[ "$rows" -eq 2 ] || fail "$rows rows of mumps, expected 2 (np 1 and 2)"
# | solver | np | unknowns | steps | Newton its | s/step | s/iteration | ... | speed-up | peak MB per rank | ...
grep '^| mumps |' <<< "$out" | awk -F'|' '{
  for (i = 4; i <= 12; ++i) gsub(/ /, "", $i)
  if ($4 !~ /^[0-9]+$/ || $4 <= 0 || $5 !~ /^[0-9]+$/ || $5 <= 0 || $6 !~ /^[0-9]+$/ || $6 <= 0 ||
      !($7 + 0 > 0) || !($8 + 0 > 0) || $14 !~ /^ *[0-9]+(\/[0-9]+)* *$/) { print "a row without figures: " $0; bad = 1 } }
  END { exit bad }' || fail "the table has rows without figures"
echo "bench_smoke: bench/bench_parallel.sh r4 gives a full table"
