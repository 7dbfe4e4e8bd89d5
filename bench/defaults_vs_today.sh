#!/usr/bin/env bash
# A pinned scene (the paper's settings: fixed dt, backward Euler, SuperLU,
# no predictor, no Jacobian reuse) against softpack's defaults (adaptive
# BDF2, MUMPS, linear predictor, jacobian_reuse 0.1, and the default
# layout.grow_threshold and layout.fill over the published runs' 0.1 and
# edge) on the same scene, one
# after the other in one run (docs/benchmarks.md):
#
#   bench/defaults_vs_today.sh [SCENE] [OUT]    (default: the paper's run 1,
#                                                 inputs/paper/constant_volume_16.yaml)
#
# REF_TOL=1e-3 adds a reference: the defaults at time.rtol = time.atol =
# REF_TOL (adaptive steps land on age divisions, so its cells divide at the
# default run's times), and prints both runs' errors against it;
# KEEP=1 reuses any of OUT/today, OUT/default and OUT/reference that has
# an energy.csv (a run of the same binary and scene) instead of running it.
#
# Prints steps, factorisations (accepted and failed attempts), failed
# attempts and wall seconds of each, their ratio, and how far the default
# run's end state is from the pinned one's (bench_compare_runs: energy at
# the common logged times, masses and centres of the cells at t_end, L2 of
# c at t_end). Pictures off.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD:-build} # the build directory whose programs run
. bench/lib.sh
scene=${1:-inputs/paper/constant_volume_16.yaml}
out=${2:-out/defaults_vs_today}
export OMP_NUM_THREADS=1
mkdir -p "$out"
echo "# bench/defaults_vs_today.sh $scene, $(date -u +%Y-%m-%d), $(nproc --all) cores"
kept() { [ "${KEEP:-0}" = 1 ] && [ -s "$out/$1/energy.csv" ]; }
kept today || "$build/softpack" run "$scene" --out "$out/today" --set output.pictures=false \
  > "$out/today.log" 2>&1
mapfile -t layout_defaults < <(defaults_of layout.grow_threshold layout.fill)
kept default || "$build/softpack" run "$scene" --out "$out/default" --set output.pictures=false \
  --set time.control=adaptive --set time.scheme=bdf2 --set solver.linear=mumps \
  --set solver.predictor=linear --set solver.jacobian_reuse=0.1 \
  "${layout_defaults[@]}" > "$out/default.log" 2>&1
read -r s0 f0 x0 w0 _ < <("$build"/bench/bench_compare_runs "$out/today" "$out/today")
read -r s1 f1 x1 w1 e m c l2 < <("$build"/bench/bench_compare_runs "$out/default" "$out/today")
printf "| run | steps | factorisations | failed | wall s |\n|---|---|---|---|---|\n"
printf "| pinned (today) | %d | %d | %d | %.1f |\n" "$s0" "$f0" "$x0" "$w0"
printf "| defaults | %d | %d | %d | %.1f |\n" "$s1" "$f1" "$x1" "$w1"
awk -v a="$w0" -v b="$w1" -v fa="$f0" -v fb="$f1" \
  'BEGIN { printf "speed-up %.2fx in wall time, %.2fx fewer factorisations\n", a / b, fa / fb }'
echo "defaults against pinned: energy $e, masses $m, centres $c, L2 of c at t_end $l2"
[ -n "${REF_TOL:-}" ] || exit 0
if ! kept reference; then
  "$build/softpack" run "$scene" --out "$out/reference" --set output.pictures=false \
    --set time.control=adaptive --set time.scheme=bdf2 --set solver.linear=mumps \
    --set solver.predictor=linear --set solver.jacobian_reuse=0.1 \
    --set time.rtol="$REF_TOL" --set time.atol="$REF_TOL" \
    "${layout_defaults[@]}" > "$out/reference.log" 2>&1
fi
read -r s2 f2 x2 w2 _ < <("$build"/bench/bench_compare_runs "$out/reference" "$out/reference")
echo "reference (defaults at rtol = atol = $REF_TOL): $s2 steps, $f2 factorisations, $x2 failed, $w2 s"
for r in default today; do
  read -r _ _ _ _ e m c l2 < <("$build"/bench/bench_compare_runs "$out/$r" "$out/reference")
  echo "$r against the reference: energy $e, masses $m, centres $c, L2 of c at t_end $l2"
done
