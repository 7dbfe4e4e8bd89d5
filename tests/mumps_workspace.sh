#!/usr/bin/env bash
# MUMPS short of memory (cxx_glue/linear/linear_mumps.cpp, docs/robustness.md),
# with a malloc that refuses large blocks (tests/malloc_cap.c, LD_PRELOAD),
# on a small 3D scene with MUMPS:
# 1. the run as it is, reporting its largest allocation M: MUMPS's
#    workspace with ICNTL(14) = 100 (the next largest must be below
#    0.45 M, so that the caps below bite on that workspace alone);
# 2. blocks above 0.8 M refused: the 100% workspace is, the 20% one
#    (about 0.6 M) is not: the run succeeds, and its energy.csv (without
#    the wall-clock columns) and cells.csv equal run 1's byte for byte
#    (the relaxation sizes the workspace, not the factors);
# 3. blocks above 0.45 M refused: the 20% workspace too: exit status 1 at
#    the first attempt ("no retry", a memory error saying what MUMPS asked
#    for), the step-0 fields written.
#   tests/mumps_workspace.sh SOFTPACK LIBMALLOC_CAP SCENE OUT_DIR
set -uo pipefail
sp=$1 lib=$2 scene=$3 out=$4
rm -rf "$out" && mkdir -p "$out"
export OMP_NUM_THREADS=1
fail() { echo "FAIL: $*" >&2; exit 1; }
run() { # run NAME [VAR=value ...]: the scene's first two steps with MUMPS
  local name=$1; shift
  env "$@" LD_PRELOAD="$lib" "$sp" run "$scene" --out "$out/$name" --quiet \
    --set solver.linear=mumps --set output.pictures=false --set time.max_steps=2 \
    > "$out/$name.log" 2>&1
}
strip_clock="$(dirname "$0")/../tools/strip_clock.sh" # energy.csv without the wall-clock columns

run free SP_MALLOC_REPORT=1 || fail "the run without a cap: $(tail -3 "$out/free.log")"
read -r largest next < <(sed -n 's/^malloc_cap: softpack largest \([0-9]*\) next \([0-9]*\)$/\1 \2/p' "$out/free.log")
[ -n "${largest:-}" ] || fail "no malloc_cap report from softpack: $(tail -3 "$out/free.log")"
echo "largest allocation $largest bytes (MUMPS's workspace at 100%), next $next"
[ "$next" -lt $((largest * 45 / 100)) ] ||
  fail "the next largest allocation ($next) is not below 0.45 x the largest ($largest)"

run lean SP_MALLOC_CAP=$((largest * 8 / 10))
status=$?
[ "$status" -eq 0 ] || fail "capped at 0.8 x $largest: exit $status: $(tail -3 "$out/lean.log")"
cmp <("$strip_clock" "$out/free/energy.csv") <("$strip_clock" "$out/lean/energy.csv") ||
  fail "capped at 0.8 x: energy.csv differs from the run without a cap"
cmp "$out/free/cells.csv" "$out/lean/cells.csv" ||
  fail "capped at 0.8 x: cells.csv differs from the run without a cap"
grep -q "(0 failed attempts retried" "$out/lean.log" ||
  fail "capped at 0.8 x: an attempt failed: $(cat "$out/lean.log")"
echo "capped at 0.8 x: the same outputs as without a cap (the 20% workspace)"

run short SP_MALLOC_CAP=$((largest * 45 / 100))
status=$?
[ "$status" -eq 1 ] || fail "capped at 0.45 x $largest: exit $status, want 1: $(tail -3 "$out/short.log")"
grep -q "softpack: error (memory): step 1 at t = 0: MUMPS: numeric factorisation failed (INFOG(1) = -13" \
  "$out/short.log" || fail "capped at 0.45 x: no memory error naming MUMPS: $(tail -3 "$out/short.log")"
grep -q "out of memory (it asked for" "$out/short.log" || fail "capped at 0.45 x: no size asked for"
[ "$(grep -c '; no retry$' "$out/short.log")" -eq 1 ] && ! grep -q "retried with" "$out/short.log" ||
  fail "capped at 0.45 x: not one attempt without retries: $(cat "$out/short.log")"
[ -f "$out/short/fields_000000.vtu" ] || fail "capped at 0.45 x: the last good state is not written"
echo "capped at 0.45 x: $(grep -o 'out of memory (it asked for [^)]*)' "$out/short.log" | head -1), exit 1, no retry"
echo ok
