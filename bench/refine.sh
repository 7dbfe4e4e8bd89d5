#!/usr/bin/env bash
# SuperLU_DIST's iterative refinement: solver.refine = true (one step per
# solve, SuperLU_DIST's own default: the baseline) against false (none,
# softpack's default) on the same scene, in one run: each with its wall
# time, phases (the solves column is what changes), Newton iterations,
# factorisations and failed attempts, then the agreement of the two runs
# (energy at every step, cells at the end).
#   bench/refine.sh [SCENE] [--set k=v ...]
#   (default: inputs/paper/embryo_8.yaml, the paper's run 5)
# The scene runs with solver.linear=superlu_dist. NP=n runs both under
# mpirun with n processes; SOFTPACK=path another binary; OUT=dir keeps the
# outputs (dir/refined, dir/unrefined).
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
scene=${1:-inputs/paper/embryo_8.yaml}
shift || true
ab_runs "$scene" refined solver.refine=true unrefined solver.refine=false \
  --set solver.linear=superlu_dist "$@"
