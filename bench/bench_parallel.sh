#!/usr/bin/env bash
# MPI runs against one process: seconds per Newton iteration and
# per step, split into assembly, factorisation, solves and the rest (the
# state's all-gather and the reductions of observables and energies, i.e.
# the communication, plus output and the C core's per-step work), speed-up,
# and peak memory (RSS) of every rank, for each direct solver and process
# count.
# Prints the tables of docs/parallel.md.
#
#   bench/bench_parallel.sh [case ...]
#   cases: r6    inputs/default.yaml (3 cells, full supports) on the ellipse
#                refined 6 times, 4 steps of dt = 2e-6
#          r7    the same refined 7 times, 1 step (serial SuperLU left out:
#                tens of minutes)
#          paper16  inputs/paper/constant_volume_16.yaml (local supports):
#                the steps between t = 0.0124 (just after the third division
#                round, 4 -> 8 cells, at t = 0.01239) and t = 0.0134, summed
#                from the per-step seconds of energy.csv
#          r4    as r6 on the default mesh (refined 4 times): a quick check
#   default: r6 r7 paper16
# The r cases pin the configuration of docs/parallel.md's table: fixed
# backward-Euler steps of dt = 2e-6, Newton from the last state with a fresh
# Jacobian each iteration (so every iteration factors), SuperLU_DIST with
# iterative refinement; PINNED="" runs them with today's defaults instead
# (adaptive BDF2, the predictor, modified Newton).
# Environment: NPS (default "1 2"), SOLVERS (default "superlu superlu_dist
# mumps"), BIN (default build/softpack), PINNED (above).
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
cases=("$@")
[ ${#cases[@]} -eq 0 ] && cases=(r6 r7 paper16)
read -r -a nps <<< "${NPS:-1 2}"
read -r -a solvers <<< "${SOLVERS:-superlu superlu_dist mumps}"
export OMP_NUM_THREADS=1 OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# A rank waiting in MPI gives its core back instead of spinning (a shared
# 2-core machine); override with OMPI_MCA_mpi_yield_when_idle=0.
export OMPI_MCA_mpi_yield_when_idle=${OMPI_MCA_mpi_yield_when_idle:-1}
bin=${BIN:-$PWD/build/softpack}
read -r -a pinned <<< "${PINNED---set time.control=fixed --set time.scheme=be --set solver.predictor=none --set solver.jacobian_reuse=0 --set solver.refine=true}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# run NP LINEAR TAG SCENE [--set ...]: prints
#   "steps its total asm fac sol mem_rank0/mem_rank1... unknowns load retries"
# (unknowns: the largest of the run with local supports, else 2 x cells x
# nodes; load: the machine's 1-minute load average just before the run;
# retries: failed Newton attempts retried with a smaller dt, whose time is
# in the totals but whose iterations are not in "Newton its")
run() {
  local np=$1 lin=$2 tag=$3 scene=$4
  shift 4
  local dir=$work/$tag.$lin.$np load
  rm -rf "$dir" && mkdir -p "$dir"
  load=$(cut -d' ' -f1 /proc/loadavg)
  mpirun -np "$np" --oversubscribe sh -c \
    '/usr/bin/time -f %M -o "$0/mem.$OMPI_COMM_WORLD_RANK" "$@"' "$dir" \
    "$bin" run "$scene" --out "$dir/out" --set output.pictures=false \
    --set output.every=100000 --set solver.linear="$lin" "$@" > "$dir/log" 2>&1 || {
      echo "FAILED: np $np $lin $tag (log: $dir/log)" >&2; cat "$dir/log" >&2; return 1; }
  local mem="" r
  for ((r = 0; r < np; ++r)); do mem+="${mem:+/}$(( $(cat "$dir/mem.$r") / 1024 ))"; done
  if [ -n "${WINDOW_T0:-}" ]; then # the steps after t = WINDOW_T0, from energy.csv
    awk -F, -v t0="$WINDOW_T0" 'NR > 1 && $2 > t0 { ++n; its += $4; s += $12; a += $13; f += $14; v += $15 }
      END { printf "%d %d %.3f %.3f %.3f %.3f ", n, its, s, a, f, v }' "$dir/out/energy.csv"
  else
    summary_phases "$dir/log" | tr '\n' ' '
  fi
  local unknowns
  unknowns=$(sed -n 's/.*at most \([0-9]*\) unknowns.*/\1/p' "$dir/log")
  local retries
  retries=$(sed -n 's/^softpack: .* steps to .* (\([0-9]*\) failed attempts.*/\1/p' "$dir/log")
  echo "$mem $unknowns $load $retries"
}

header() {
  echo
  echo "### $1"
  echo
  echo "| solver | np | unknowns | steps | Newton its | s/step | s/iteration | assembly/it | factorisation/it | solves/it | rest/it | speed-up | peak MB per rank | load before | retries |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
}

# row LIN NP "steps its total asm fac sol mem unknowns" BASE_TOTAL
row() {
  local lin=$1 np=$2 base=$4
  read -r steps its total as fa so mem unknowns load retries <<< "$3"
  awk -v lin="$lin" -v np="$np" -v steps="$steps" -v its="$its" -v total="$total" -v as="$as" \
      -v fa="$fa" -v so="$so" -v mem="$mem" -v base="$base" -v unk="$unknowns" -v load="$load" -v retries="$retries" 'BEGIN {
    printf "| %s | %d | %s | %d | %d | %.2f | %.2f | %.3f | %.3f | %.3f | %.3f | %s | %s | %s | %s |\n", lin, np, unk, steps, its,
      total / steps, total / its, as / its, fa / its, so / its, (total - as - fa - so) / its,
      (base > 0 ? sprintf("%.2f", base / total) : "-"), mem, load, retries }'
}

table() {  # table TITLE TAG SKIP_SOLVER SCENE [--set ...]
  local title=$1 tag=$2 skip=$3
  shift 3
  header "$title"
  local lin np r base
  for lin in "${solvers[@]}"; do
    [ "$lin" = "$skip" ] && continue
    base=0
    for np in "${nps[@]}"; do
      r=$(run "$np" "$lin" "$tag" "$@")
      [ "$np" = 1 ] && base=$(echo "$r" | cut -d' ' -f3)
      row "$lin" "$np" "$r" "$base"
    done
  done
}

echo "machine: $(nproc --all) cores, $(lscpu | sed -n 's/^Model name: *//p'), load average $(cut -d' ' -f1-3 /proc/loadavg) at start"
for c in "${cases[@]}"; do
  case $c in
    r4) table "Ellipse refined 4 times, 3 cells, full supports (4 steps of dt = 2e-6)" r4 "" \
          inputs/default.yaml --set time.dt=2e-6 --set time.t_end=8e-6 "${pinned[@]}" ;;
    r6) table "Ellipse refined 6 times, 3 cells, full supports (4 steps of dt = 2e-6)" r6 "" \
          inputs/default.yaml --set mesh.refinements=6 --set time.dt=2e-6 --set time.t_end=8e-6 \
          "${pinned[@]}" ;;
    r7) table "Ellipse refined 7 times, 3 cells, full supports (1 step of dt = 2e-6)" r7 superlu \
          inputs/default.yaml --set mesh.refinements=7 --set time.dt=2e-6 --set time.t_end=2e-6 \
          "${pinned[@]}" ;;
    paper16) # the window's steps from energy.csv's per-step seconds
      WINDOW_T0=0.0124 table "Paper run 1 (16 cells, local supports): the steps from t = 0.0124 to 0.0134 (8 cells)" \
        p16 "" inputs/paper/constant_volume_16.yaml --set time.t_end=0.0134 ;;
    *) echo "unknown case $c" >&2; exit 2 ;;
  esac
done
echo
echo "load average $(cut -d' ' -f1-3 /proc/loadavg) at the end"
