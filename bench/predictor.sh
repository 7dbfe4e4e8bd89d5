#!/usr/bin/env bash
# Newton's initial guess: solver.predictor = none (the last state: the
# baseline) against linear (the last state plus its last increment) on the
# same scene, in one run: each with its wall time, phases, Newton
# iterations, factorisations and failed attempts, then the agreement of
# the two runs (energy at every step, cells at the end).
#   bench/predictor.sh [SCENE] [--set k=v ...]
#   (default: inputs/paper/constant_volume_16.yaml)
# NP=n runs both under mpirun with n processes; SOFTPACK=path another
# binary; OUT=dir keeps the outputs (dir/none, dir/linear).
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
scene=${1:-inputs/paper/constant_volume_16.yaml}
shift || true
ab_runs "$scene" none solver.predictor=none linear solver.predictor=linear "$@"
