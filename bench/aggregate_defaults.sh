#!/usr/bin/env bash
# The aggregate with the defaults against the published (pinned) run, at
# the error each buys: inputs/aggregate_256.yaml (fixed
# backward-Euler steps of 2e-4 with algorithm 2's ramp, SuperLU_DIST, the
# published support rule) and inputs/aggregate_256_defaults.yaml (the same
# scene with softpack's defaults), both cut at CELLS cells (16 or 64), each
# measured against a reference: the defaults' scene at rtol = atol = REF_TOL
# (1e-3). One after the other in one command:
#
#   bench/aggregate_defaults.sh [CELLS] [OUT]      (default 16, out/aggregate_defaults)
#   NP=2 bench/aggregate_defaults.sh 64            (each run under mpirun -np 2)
#   TOLS="1e-2 3e-2 1e-1" bench/aggregate_defaults.sh   (the defaults' scene at
#                                                     these tolerances too)
#   REUSE=1 ...                                     (table the runs already in OUT)
#
# Prints per run: steps, factorisations (accepted and failed attempts),
# failed attempts, support changes, wall seconds, and its distance from the
# reference (bench_compare_runs: energy at the multiples of 5e-4 both log,
# masses and centres of the cells at the end, L2 of c at the end). CELLS
# = 16: to t = 0.005 (the fourth division at 0.004, then 0.001 of
# packing); 64: to t = 0.007.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD:-build}
cells=${1:-16}
out=${2:-out/aggregate_defaults}
ref_tol=${REF_TOL:-1e-3}
tols=${TOLS:-1e-2}
case $cells in
  16) t_end=0.005 ;;
  64) t_end=0.007 ;;
  *) echo "bench/aggregate_defaults.sh: CELLS must be 16 or 64, got '$cells'" >&2; exit 2 ;;
esac
export OMP_NUM_THREADS=1
launch=()
[ "${NP:-1}" -gt 1 ] && launch=(mpirun --allow-run-as-root --oversubscribe -np "$NP")
cut=(--set division.max_cells="$cells" --set time.t_end="$t_end" --set output.interval=5e-4
     --set output.every=100000000 --set output.pictures=false)
mkdir -p "$out"
run() { # NAME SCENE [--set ...]
  local name=$1 scene=$2
  shift 2
  [ "${REUSE:-0}" = 1 ] && [ -f "$out/$name/energy.csv" ] && return 0
  rm -rf "${out:?}/$name"
  "${launch[@]}" "${SOFTPACK:-$build/softpack}" run "$scene" --out "$out/$name" "${cut[@]}" "$@" \
    > "$out/$name.log" 2>&1
}
echo "# bench/aggregate_defaults.sh $cells, NP=${NP:-1}, $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc --all) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
run reference inputs/aggregate_256_defaults.yaml --set time.rtol="$ref_tol" --set time.atol="$ref_tol"
run pinned inputs/aggregate_256.yaml
for tol in $tols; do
  run "defaults_$tol" inputs/aggregate_256_defaults.yaml --set time.rtol="$tol" --set time.atol="$tol"
done
changes() { awk -F, 'NR == 1 { for (j = 1; j <= NF; ++j) if ($j == "support_changed") c = j; next }
                    { n += $c } END { print n }' "$out/$1/energy.csv"; }
echo
echo "| run | steps | factorisations | failed attempts | support changes | wall s | energy | masses | centres | L2 of c |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for name in pinned $(for t in $tols; do echo "defaults_$t"; done) reference; do
  read -r s f x w e m c l2 < <("$build"/bench/bench_compare_runs "$out/$name" "$out/reference")
  label=$name
  [ "$name" = reference ] && label="reference (defaults at $ref_tol)" && e=- m=- c=- l2=-
  printf "| %s | %d | %d | %d | %d | %.1f | %s | %s | %s | %s |\n" "$label" "$s" "$f" "$x" \
    "$(changes "$name")" "$w" "$e" "$m" "$c" "$l2"
done
