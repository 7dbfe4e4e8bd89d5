#!/usr/bin/env bash
# Issue 28's small reproducer (tests/scenes/growth_two.yaml, which
# tests/growth_steps.sh runs too): two touching cells growing in the paper's
# ellipse (no division: max_cells 2 only stops the source at 10x), the
# defaults otherwise (adaptive BDF2 at 1e-2), run with full supports, local
# supports at the default margin, and local supports at the aggregate's
# narrow margins (margin 4 d, band 2 d, cores c >= 0.3). One process.
#   bench/growth_transient.sh [--set k=v ...]   (applied to every variant)
# SOFTPACK=path runs another binary; OUT=dir keeps the runs in dir/<variant>
# (otherwise a temporary directory, removed at the end); VARIANTS="full
# local narrow" picks the variants.
# Per variant: accepted steps, rejected attempts (failed_attempts), support
# changes, Newton iterations, factorisations (failed attempts' included),
# wall seconds, and the median error estimate of the steps right after a
# support change (the step following a row with support_changed = 1)
# against that of the other estimated steps (estimate >= 0).
# REF_DT=2.5e-6 adds, per variant, a reference on the same supports
# (fixed-dt BDF2 at REF_DT; kept in OUT/ref_<variant> and reused when
# there) and each run's errors against it at t_end (bench_compare_runs:
# energy over the logged times, masses and centres at t_end, relative L2
# of all cells' c); BUILD=dir names the build whose bench_compare_runs
# reads them (default build).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${SOFTPACK:-build/softpack}
out=${OUT:-$(mktemp -d)}
variants=${VARIANTS:-full local narrow}
export OMP_NUM_THREADS=1
scene=tests/scenes/growth_two.yaml
mkdir -p "$out"
sets_of() {
  case $1 in
    full) echo "--set layout.support=full" ;;
    local) echo "--set layout.support=local" ;;
    narrow) echo "--set layout.support=local --set layout.margin=4 --set layout.band=2 --set layout.core_threshold=0.3" ;;
    *) echo "unknown variant $1" >&2; return 2 ;;
  esac
}
rows=()
for v in $variants; do
  t0=$(date +%s.%N)
  # shellcheck disable=SC2046
  "$bin" run "$scene" --out "$out/$v" $(sets_of "$v") "$@" > "$out/$v.log" 2>&1 \
      || { echo "$v failed:"; tail -5 "$out/$v.log"; exit 1; }
  t1=$(date +%s.%N)
  wall=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')
  errs=
  if [ -n "${REF_DT:-}" ]; then
    if [ ! -s "$out/ref_$v/energy.csv" ]; then
      # shellcheck disable=SC2046
      "$bin" run "$scene" --out "$out/ref_$v" $(sets_of "$v") --set time.control=fixed \
          --set time.scheme=bdf2 --set time.dt="$REF_DT" --set output.interval=5e-4 \
          > "$out/ref_$v.log" 2>&1 || { echo "reference $v failed:"; tail -5 "$out/ref_$v.log"; exit 1; }
    fi
    read -r _ _ _ _ e m c l2 < <("${BUILD:-build}"/bench/bench_compare_runs "$out/$v" "$out/ref_$v")
    errs=" $e | $m | $c | $l2 |"
  fi
  rows+=("$(awk -F, -v v="$v" -v wall="$wall" -v errs="$errs" '
    NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
    $(col["step"]) == 0 { prev = 0; next }
    { ++steps; rej += $(col["failed_attempts"]); chg += $(col["support_changed"])
      its += $(col["newton_its"]); fac += $(col["factorisations"]) + $(col["failed_factorisations"])
      e = $(col["error_estimate"])
      if (e >= 0) { if (prev) a[++na] = e; else b[++nb] = e }
      prev = $(col["support_changed"]) }
    function median(x, n,   i, j, t) {
      if (n == 0) return "-"
      for (i = 2; i <= n; ++i) { t = x[i]; for (j = i - 1; j >= 1 && x[j] > t; --j) x[j + 1] = x[j]; x[j + 1] = t }
      return sprintf("%.3g", n % 2 ? x[(n + 1) / 2] : (x[n / 2] + x[n / 2 + 1]) / 2)
    }
    END { printf "| %s | %d | %d | %d | %d | %d | %s | %s (%d) | %s (%d) |%s", v, steps, rej, chg, its, fac, wall,
                 median(a, na), na, median(b, nb), nb, errs }' "$out/$v/energy.csv")")
done
echo
echo "command: ${SOFTPACK:+SOFTPACK=$SOFTPACK }bench/growth_transient.sh $*  ($(git rev-parse --short HEAD 2>/dev/null || echo '?'))"
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'), one process, OMP_NUM_THREADS=1, load $(cut -d' ' -f1-3 /proc/loadavg)"
echo
head="| supports | accepted steps | rejected attempts | support changes | Newton its | factorisations | wall s | median estimate after a change (steps) | median estimate otherwise (steps) |"
rule="|---|---|---|---|---|---|---|---|---|"
[ -n "${REF_DT:-}" ] && head="$head energy error | mass error | centre error | L2 error |" && rule="$rule---|---|---|---|"
echo "$head"
echo "$rule"
printf '%s\n' "${rows[@]}"
[ -n "${OUT:-}" ] || rm -rf "$out"
