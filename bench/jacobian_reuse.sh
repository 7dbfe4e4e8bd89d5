#!/usr/bin/env bash
# Modified Newton against Newton's method on the same scene, in one run:
# the scene with solver.jacobian_reuse = 0 (a new Jacobian every
# iteration: the baseline) and = THETA, each with its wall time, phases,
# Newton iterations, factorisations and failed attempts, then the
# agreement of the two runs (energy at every step, cells at the end).
#   bench/jacobian_reuse.sh [SCENE] [THETA] [--set k=v ...]
#   (defaults: inputs/paper/constant_volume_16.yaml, 0.1)
# NP=n runs both under mpirun with n processes; SOFTPACK=path another
# binary; OUT=dir keeps the outputs (dir/newton, dir/reuse).
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
scene=${1:-inputs/paper/constant_volume_16.yaml}
theta=${2:-0.1}
shift 2 || shift $#
bin=${SOFTPACK:-build/softpack}
out=${OUT:-$(mktemp -d)}
np=${NP:-1}
launch=()
[ "$np" -gt 1 ] && launch=(mpirun --allow-run-as-root -np "$np")
export OMP_NUM_THREADS=1
for run in newton reuse; do
  r=0
  [ $run = reuse ] && r=$theta
  /usr/bin/time -f "$run: %e s wall, %M kB peak (rank 0)" "${launch[@]}" "$bin" run "$scene" \
      --out "$out/$run" --set solver.jacobian_reuse=$r --set output.pictures=false "$@" 2>&1 |
    grep -v "^softpack: step\|^  " | sed "s/^/$run: /"
done
echo "per accepted step (energy.csv): Newton iterations, factorisations, failed attempts, seconds"
for run in newton reuse; do
  awk -F, -v run=$run 'NR > 1 && $1 > 0 { s++; it += $4; f += $19; fa += $20; sec += $12; fs += $14 }
    END { printf "  %s: %d steps, %.2f iterations/step, %.2f factorisations/step, %d failed attempts, %.3f s/step (factorisation %.3f)\n",
          run, s, it / s, f / s, fa, sec / s, fs / s }' "$out/$run/energy.csv"
done
compare_runs "$out/newton" "$out/reuse"
[ -n "${OUT:-}" ] || rm -rf "$out"
