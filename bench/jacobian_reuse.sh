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
ab_runs "$scene" newton solver.jacobian_reuse=0 reuse solver.jacobian_reuse="$theta" "$@"
