#!/usr/bin/env bash
# The work-precision report (docs/time-stepping.md): error against wall time
# and against factorisations for fixed-dt backward Euler (the paper's
# method) at dt, dt/2, dt/4, dt/8, adaptive BE and adaptive BDF2 at several
# tolerances, and the default configuration, each against a reference run.
#
#   bench/work_precision.sh a [OUT]   three overlapping cells relaxing,
#                                     inputs/bench/relax_3.yaml (64 x 64, T = 0.02)
#   bench/work_precision.sh b [OUT]   the paper's run 5, inputs/paper/embryo_8.yaml
#                                     (1 -> 8 cells, divisions; T = 0.016)
#   bench/work_precision.sh c2 [OUT]  the paper's run 2, inputs/paper/growth_12.yaml
#                                     (growth by the mass criterion; local supports,
#                                     layout.support auto, as the scene runs),
#                                     cut at T = T_END (default 0.006: 8 cells, after
#                                     the third generation's staggered divisions)
#   bench/work_precision.sh c16 [OUT] the aggregate cut at 16 cells (local supports,
#                                     growth, age divisions; T = T_END, 0.005) as
#                                     bench/aggregate_defaults.sh 16 runs it:
#                                     inputs/aggregate_256_defaults.yaml, and the
#                                     published settings (inputs/aggregate_256.yaml)
#                                     as the row "pinned"; on NP (default 2) processes
#
# Environment: REF_TOL (the reference: adaptive BDF2 at rtol = atol =
# REF_TOL; default 1e-5 on a), REF_DT (instead: fixed-dt BDF2 at REF_DT;
# default on b, c2 and c16: dt / 128, 16x below the finest fixed step), TOLS_BE, TOLS_BDF2 (tolerance lists), FIXED
# (divisors of dt, default "1 2 4 8"), SOLVER (extra --set options of every
# run but "today"; default: the program's defaults), SKIP_REF=1 (reuse the
# reference in OUT), KEEP=1 (keep the runs OUT holds from an interrupted
# report: a run that finished left OUT/NAME.done; with SKIP_REF=1 KEEP=1 and
# the adaptive rows' directories and .done files removed, only those rows
# run again), REF_CHECK=1 (also the reference at 2 x its dt, "ref_2dt", and
# its distance from the reference: the reference's own error is a third of
# that distance at second order, about the distance itself at first order).
# Every run logs at multiples of output.interval (INTERVAL, default 0.002;
# 5e-4 on c16), where the energies are compared; on c2 and c16 at those
# multiples only (their other common times can fall between two runs'
# divisions of a cell).
# SETS: more --set options of every run, the reference's too (e.g. SETS="--set
# layout.support=full" on c2, which runs on local supports as the scene does).
# OUT/NAME.commit records the program (`softpack --version`) each row ran.
# Rows: name, steps, factorisations (accepted and failed attempts), failed
# attempts, wall seconds (sum of the per-step seconds), then the errors
# against the reference (bench/bench_compare_runs.c): the largest relative
# energy error at the common times, the largest relative mass error and
# centre distance of the cells at T, and the relative L2 norm of the
# fields' difference at T. "today" is the configuration before
# time.control existed: fixed BE at dt with SuperLU, no predictor, no
# Jacobian reuse. Every other run takes the program's default solver
# settings (`softpack keys`) over what the scene pins, and "default" the
# program's defaults of time.* too: the paper's scenes pin the paper's. Plots: OUT/wp_<scene>_{factorisations,wall}.png.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD:-build} # the build directory whose programs run
. bench/lib.sh
which=${1:-a}
cut=() pinned= launch=() interval=0.002 energy_at=
case "$which" in
  a) scene=inputs/bench/relax_3.yaml ;;
  b) scene=inputs/paper/embryo_8.yaml ;;
  c2) scene=inputs/paper/growth_12.yaml cut=(--set time.t_end="${T_END:-0.006}") energy_at=1 ;;
  c16) scene=inputs/aggregate_256_defaults.yaml pinned=inputs/aggregate_256.yaml interval=5e-4
       cut=(--set division.max_cells=16 --set time.t_end="${T_END:-0.005}")
       launch=(mpiexec --allow-run-as-root --oversubscribe -np "${NP:-2}") energy_at=1 ;;
  *) echo "usage: bench/work_precision.sh a|b|c2|c16 [OUT]" >&2; exit 2 ;;
esac
out=${2:-out/work_precision_$which}
ref_tol=${REF_TOL:-1e-5}
ref_dt=${REF_DT:-}
tols_be=${TOLS_BE:-"1e-1 3e-2 1e-2"}
tols_bdf2=${TOLS_BDF2:-"3e-1 1e-1 3e-2 1e-2"}
fixed=${FIXED:-"1 2 4 8"}
interval=${INTERVAL:-$interval}
[ -n "$energy_at" ] && energy_at=$interval # c: energies at its multiples only (bench_compare_runs)
read -r -a solver <<< "${SOLVER:-}"
read -r -a sets <<< "${SETS:-}"
export OMP_NUM_THREADS=1
mkdir -p "$out"
common=(--set output.interval="$interval" --set output.every=100000000
        --set output.pictures=false "${cut[@]}" "${sets[@]}")
dt=$(awk '/^time:/ { if (match($0, /dt: *[0-9.eE+-]+/)) { s = substr($0, RSTART, RLENGTH);
       sub(/dt: */, "", s); print s } }' "${pinned:-$scene}")
dt=${dt:-2e-4}
[ "$which" != a ] && [ -z "${REF_TOL:-}" ] && [ -z "$ref_dt" ] &&
  ref_dt=$(awk -v dt="$dt" 'BEGIN { printf "%.10g", dt / 128 }')
mapfile -t fast < <(defaults_of solver.linear solver.predictor solver.jacobian_reuse \
                      solver.jacobian_carry)
mapfile -t defaults < <(defaults_of time.control time.scheme time.rtol time.atol \
                          layout.grow_threshold layout.fill)
[ ${#fast[@]} = 8 ] && [ ${#defaults[@]} = 12 ] ||
  { echo "bench/work_precision.sh: cannot read the defaults from softpack keys" >&2; exit 2; }
solver=("${fast[@]}" "${solver[@]}")

run() { # NAME SET... (the scene: $run_scene, default $scene)
  local name=$1 s=${run_scene:-$scene}
  shift
  if [ "${KEEP:-0}" = 1 ] && [ -f "$out/$name.done" ]; then return 0; fi
  echo "softpack run $s $* (-> $out/$name)" >&2
  rm -f "$out/$name.done"
  "$build/softpack" --version > "$out/$name.commit"
  "${launch[@]}" "$build/softpack" run "$s" --out "$out/$name" "${common[@]}" "$@" \
      > "$out/$name.log" 2>&1 || { echo "run $name failed: see $out/$name.log" >&2; return 1; }
  touch "$out/$name.done"
}

echo "# bench/work_precision.sh $which, $(date -u +%Y-%m-%d), $(nproc --all) cores, scene $scene"
if [ -n "$ref_dt" ]; then
  echo "# reference: fixed-dt BDF2, dt = $ref_dt; solver options: ${solver[*]}"
  ref=(--set time.control=fixed --set time.scheme=bdf2 --set time.dt="$ref_dt")
else
  echo "# reference: adaptive BDF2, rtol = atol = $ref_tol; solver options: ${solver[*]}"
  ref=(--set time.control=adaptive --set time.scheme=bdf2 --set time.rtol="$ref_tol"
       --set time.atol="$ref_tol")
fi
if [ "${SKIP_REF:-0}" != 1 ]; then
  [ "${KEEP:-0}" = 1 ] || rm -f "$out"/*.done
  run ref "${ref[@]}" "${solver[@]}"
fi
if [ "${REF_CHECK:-0}" = 1 ]; then
  [ -n "$ref_dt" ] || { echo "bench/work_precision.sh: REF_CHECK needs a fixed-dt reference" >&2; exit 2; }
  ref2=("${ref[@]}")
  ref2[${#ref2[@]} - 1]=time.dt=$(awk -v d="$ref_dt" 'BEGIN { printf "%.10g", 2 * d }')
  run ref_2dt "${ref2[@]}" "${solver[@]}" &&
    echo "# the reference at 2 x its dt against it: $("$build"/bench/bench_compare_runs "$out/ref_2dt" "$out/ref" $energy_at | cut -d' ' -f5-) (energy mass centre L2)"
fi
names=()
run today --set time.control=fixed --set time.scheme=be --set time.dt="$dt" \
    --set solver.linear=superlu --set solver.predictor=none --set solver.jacobian_reuse=0 &&
  names+=(today)
for f in $fixed; do
  d=$(awk -v dt="$dt" -v f="$f" 'BEGIN { printf "%.10g", dt / f }')
  run "fixed_be_dt$f" --set time.control=fixed --set time.scheme=be --set time.dt="$d" \
      "${solver[@]}" && names+=("fixed_be_dt$f")
done
for tol in $tols_be; do
  run "adaptive_be_$tol" --set time.control=adaptive --set time.scheme=be \
      --set time.rtol="$tol" --set time.atol="$tol" "${solver[@]}" && names+=("adaptive_be_$tol")
done
for tol in $tols_bdf2; do
  run "adaptive_bdf2_$tol" --set time.control=adaptive --set time.scheme=bdf2 \
      --set time.rtol="$tol" --set time.atol="$tol" "${solver[@]}" &&
    names+=("adaptive_bdf2_$tol")
done
if [ -n "$pinned" ]; then # the published settings, as they are
  run_scene=$pinned run pinned && names+=(pinned)
fi
run default "${defaults[@]}" "${solver[@]}" && names+=(default)

printf "| %-20s | %5s | %6s | %6s | %8s | %9s | %9s | %9s | %9s | %s |\n" run steps facts failed \
  wall_s energy mass centre L2 program
echo "|---|---|---|---|---|---|---|---|---|---|"
points=()
for n in "${names[@]}"; do
  read -r steps facts failed wall e m c l2 < <("$build"/bench/bench_compare_runs "$out/$n" "$out/ref" $energy_at)
  printf "| %-20s | %5d | %6d | %6d | %8.1f | %9.2e | %9.2e | %9.2e | %9.2e | %s |\n" "$n" "$steps" \
    "$facts" "$failed" "$wall" "$e" "$m" "$c" "$l2" \
    "$(sed -n 's/.*git \([0-9a-f]*\).*/\1/p' "$out/$n.commit" 2>/dev/null | cut -c1-7)"
  series=${n%_*}
  case "$n" in fixed_*) series=fixed_be ;; today|default|pinned) series=$n ;; esac
  points+=("$series $facts $l2 $wall")
done
for axis in factorisations wall; do
  for p in "${points[@]}"; do
    read -r s f l2 w <<< "$p"
    if [ "$axis" = factorisations ]; then echo "$s $f $l2"; else echo "$s $w $l2"; fi
  done | "$build"/bench/bench_wp_plot "$out/wp_${which}_$axis.png" \
    "$( [ "$axis" = wall ] && echo "wall seconds" || echo "factorisations")" \
    "relative L2 error of c at T" "work-precision, scene $which ($(date -u +%Y-%m-%d))"
done
echo "# plots: $out/wp_${which}_factorisations.png, $out/wp_${which}_wall.png"
