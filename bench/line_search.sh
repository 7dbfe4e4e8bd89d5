#!/usr/bin/env bash
# Newton's update length: solver.line_search = full (full steps, the
# default: the baseline) against backtrack (NOX's backtracking line
# search) on the same scene, in one run: each with its wall time, phases,
# steps, Newton iterations, factorisations and failed attempts, the ratio
# of the wall times, then the agreement of the two runs (energy at every
# step of the same t, cells at the end, divisions).
#   bench/line_search.sh [SCENE] [--set k=v ...]
#   (default: inputs/aggregate_256.yaml to t = 0.0075, 1 -> 64 cells)
# NP=n runs both under mpirun with n processes (NP=2 as measured in
# docs/benchmarks.md); SOFTPACK=path another binary; OUT=dir keeps the
# outputs (dir/full, dir/backtrack).
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
scene=${1:-inputs/aggregate_256.yaml}
shift || true
extra=()
[ "$scene" = inputs/aggregate_256.yaml ] && [ $# -eq 0 ] && extra=(--set time.t_end=0.0075)
ab_runs "$scene" full solver.line_search=full backtrack solver.line_search=backtrack \
  "${extra[@]}" "$@"
