#!/usr/bin/env bash
# Refactors keep outputs byte-identical: run every scene of inputs/ and
# tests/scenes/ with two softpack binaries and compare what they write.
#
#   tools/compare_outputs.sh OLD_SOFTPACK NEW_SOFTPACK [NP...] [-- SCENE...]
#   tools/compare_outputs.sh --tolerance OLD NEW [NP...] [-- SCENE...]
#
# --tolerance (tools/compare_tolerance_all.sh): the same runs compared by
# tools/compare_tolerance.py instead of cmp (1e-10 relative in energy,
# masses and centres, Newton iterations counted); both binaries run (no
# cache).
#
# NP: the process counts to compare on (default "1 2"); on more than one
# process every run uses solver.linear=superlu_dist, which is bitwise
# reproducible (MUMPS' parallel assembly order is not, docs/restart.md).
# Each scene is cut with time.max_steps (the table below) past its first
# division and its first support change where it has them; pictures are
# off. Compared with cmp: energy.csv without its wall-clock columns
# (seconds, assembly_s, factorisation_s, solves_s, supports_s), cells.csv,
# divisions.csv. Prints a line per run (steps, divisions, support changes
# reached) and exits 1 if any file differs or a run's status differs.
# SET="k=v ...": more --set overrides for every run, after the script's
# own (so SET=solver.linear=gmres_ilu compares that solver on every NP).
# COMPARE_CACHE=DIR keeps OLD's outputs in DIR and reuses them when there
# (for a series of comparisons against one baseline binary).
set -uo pipefail
tolerance=
[ "${1:-}" = --tolerance ] && { tolerance=" beyond the tolerance"; shift; }
old=$1 new=$2
shift 2
nps=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do nps+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
[ ${#nps[@]} -eq 0 ] && nps=(1 2)
cd "$(dirname "$0")/.."
export OMP_NUM_THREADS=1

# scene -> steps: past the first division and the first support change
declare -A cut=(
  [inputs/default.yaml]=30
  [inputs/divide_1_2_4.yaml]=60
  [inputs/embryo/lineage_4.yaml]=100
  [inputs/label_image.yaml]=20
  [inputs/aggregate_256.yaml]=14
  [inputs/bench/relax_3.yaml]=20
  [inputs/paper/constant_volume_16.yaml]=25
  [inputs/paper/embryo_8.yaml]=40
  [inputs/paper/growth_12.yaml]=45
  [inputs/paper/growth_calibrated_12.yaml]=45
  [inputs/paper/growth_shape_12.yaml]=45
  [inputs/paper/growth_shape_calibrated_12.yaml]=45
  [inputs/paper/growth_shape_implicit_12.yaml]=45
  [inputs/paper/growth_shape_strong_12.yaml]=45
  [inputs/paper/shape_delta_1e5.yaml]=20
  [inputs/paper/shape_delta_2e5.yaml]=20
  [inputs/paper/shape_delta_5e4.yaml]=20
  [tests/scenes/divide_1_2_4.yaml]=60
  [tests/scenes/divide_eight.yaml]=60
  [tests/scenes/ellipse_minimal.yaml]=20
  [tests/scenes/five_overlapping.yaml]=20
  [tests/scenes/local_edge.yaml]=40
  [tests/scenes/local_push.yaml]=40
  [tests/scenes/local_short.yaml]=40
  [tests/scenes/overlap_hard.yaml]=20
  [tests/scenes/rectangle_full.yaml]=10
  [tests/scenes/restart_grow.yaml]=60
  [tests/scenes/two_overlapping.yaml]=20
)
scenes=("$@")
[ ${#scenes[@]} -eq 0 ] && scenes=($(printf '%s\n' "${!cut[@]}" | sort))

work=$(mktemp -d "${TMPDIR:-/tmp}/softpack_compare.XXXXXX")
trap 'rm -rf "$work"' EXIT

# energy.csv without the wall-clock columns
strip_clock() { tools/strip_clock.sh "$1"; }

run_one() { # BINARY NP SCENE DIR
  local sp=$1 np=$2 scene=$3 dir=$4 launch=()
  local sets=(--set "time.max_steps=${cut[$scene]:-20}" --set output.pictures=false)
  if [ "$np" -gt 1 ]; then
    launch=(mpiexec --allow-run-as-root --oversubscribe -np "$np")
    sets+=(--set solver.linear=superlu_dist)
  fi
  for kv in ${SET:-}; do sets+=(--set "$kv"); done
  "${launch[@]}" "$sp" run "$scene" --quiet --out "$dir" "${sets[@]}" > "$dir.log" 2>&1
}

failures=0
for np in "${nps[@]}"; do
  for scene in "${scenes[@]}"; do
    if [ -n "$tolerance" ]; then
      sets=("time.max_steps=${cut[$scene]:-20}")
      [ "$np" -gt 1 ] && sets+=(solver.linear=superlu_dist)
      for kv in ${SET:-}; do sets+=("$kv"); done
      tools/compare_tolerance.py "$old" "$new" "$np" "$scene" "${sets[@]}" ||
        failures=$((failures + 1))
      continue
    fi
    name=$(echo "$scene${SET:+ $SET}" | tr '/ =' '___')
    a=$work/old_${np}_$name b=$work/new_${np}_$name
    if [ -n "${COMPARE_CACHE:-}" ]; then
      mkdir -p "$COMPARE_CACHE"
      a=$COMPARE_CACHE/old_${np}_$name
    fi
    if [ -n "${COMPARE_CACHE:-}" ] && [ -f "$a.status" ]; then
      sa=$(cat "$a.status")
    else
      rm -rf "$a"
      run_one "$old" "$np" "$scene" "$a"; sa=$?
      echo "$sa" > "$a.status"
    fi
    run_one "$new" "$np" "$scene" "$b"; sb=$?
    verdict=same
    [ "$sa" -eq "$sb" ] || verdict="status $sa -> $sb"
    for f in energy.csv cells.csv divisions.csv; do
      if [ -f "$a/$f" ] || [ -f "$b/$f" ]; then
        if [ "$f" = energy.csv ]; then
          cmp -s <(strip_clock "$a/$f" 2>/dev/null) <(strip_clock "$b/$f" 2>/dev/null) ||
            verdict="$f differs"
        else
          cmp -s "$a/$f" "$b/$f" || verdict="$f differs"
        fi
      fi
    done
    steps=0 divs=0 changes=0
    if [ -f "$b/energy.csv" ]; then
      steps=$(($(wc -l < "$b/energy.csv") - 2))
      changes=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "support_changed") c = i }
                         NR > 1 && $c == 1 { ++n } END { print n + 0 }' "$b/energy.csv")
    fi
    [ -f "$b/divisions.csv" ] && divs=$(($(wc -l < "$b/divisions.csv") - 1))
    printf '%-48s np %d  status %d  steps %4d  divisions %3d  support changes %3d  %s\n' \
      "$scene" "$np" "$sb" "$steps" "$divs" "$changes" "$verdict"
    [ "$verdict" = same ] || failures=$((failures + 1))
  done
done
echo "compare_outputs: $failures run(s) differ$tolerance"
[ "$failures" -eq 0 ]
