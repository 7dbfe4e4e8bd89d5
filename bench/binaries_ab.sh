#!/usr/bin/env bash
# Per-step cost of two softpack binaries on one scene (the
# Newton solve on NOX-Epetra, then on NOX-Thyra): ROUNDS rounds, each
# running OLD and NEW at the same time (one process each: on a machine
# shared with other work both see the same load at the same moments).
# Per run the phases are summed over energy.csv's rows (assembly_s,
# factorisation_s, solves_s, seconds); printed: per binary the median and
# the minimum over the rounds (the minimum is the run least slowed by
# other work), and NEW / OLD of each. Also says whether the first round's
# two runs wrote the same energy.csv columns 1-11 (steps, t, dt, Newton
# iterations, cells, the energy and its parts).
#   bench/binaries_ab.sh OLD_SOFTPACK NEW_SOFTPACK SCENE ROUNDS [--set k=v ...]
set -uo pipefail
old=$1 new=$2 scene=$3 rounds=$4
shift 4
export OMP_NUM_THREADS=1
out=$(mktemp -d "${TMPDIR:-/tmp}/softpack_ab.XXXXXX")
trap 'rm -rf "$out"' EXIT
phases() {  # energy.csv -> "assembly factorisation solves seconds"
  awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
    { a += $c["assembly_s"]; f += $c["factorisation_s"]; s += $c["solves_s"]; t += $c["seconds"] }
    END { printf "%.4f %.4f %.4f %.4f\n", a, f, s, t }' "$1"
}
for r in $(seq "$rounds"); do
  "$old" run "$scene" --quiet --out "$out/old$r" --set output.pictures=false "$@" > /dev/null 2>&1 &
  "$new" run "$scene" --quiet --out "$out/new$r" --set output.pictures=false "$@" > /dev/null 2>&1 ||
    { echo "new run $r failed"; exit 1; }
  wait $! || { echo "old run $r failed"; exit 1; }
  for which in old new; do echo "$which $(phases "$out/$which$r/energy.csv")" >> "$out/phases"; done
done
same=yes
cut -d, -f1-11 "$out/old1/energy.csv" | cmp -s - <(cut -d, -f1-11 "$out/new1/energy.csv") || same=no
echo "$scene $* ($rounds rounds, steps $(($(wc -l < "$out/new1/energy.csv") - 2)), energy.csv columns 1-11 identical: $same)"
awk '{ n[$1]++; for (k = 2; k <= 5; ++k) v[$1, n[$1], k] = $k }
  function sorted(w, k, x,   m, i, j, t) {
    m = n[w]; for (i = 1; i <= m; ++i) x[i] = v[w, i, k]
    for (i = 1; i <= m; ++i) for (j = i + 1; j <= m; ++j) if (x[j] < x[i]) { t = x[i]; x[i] = x[j]; x[j] = t }
    return m }
  function median(w, k,   m, x) { m = sorted(w, k, x); return m % 2 ? x[(m + 1) / 2] : (x[m / 2] + x[m / 2 + 1]) / 2 }
  function least(w, k,   x) { sorted(w, k, x); return x[1] }
  END { split("assembly_s factorisation_s solves_s seconds", name)
    printf "  %-16s %10s %10s %9s %10s %10s %9s\n", "phase (s)", "old med", "new med", "new/old", "old min", "new min", "new/old"
    for (k = 2; k <= 5; ++k) { a = median("old", k); b = median("new", k); c = least("old", k); d = least("new", k)
      printf "  %-16s %10.3f %10.3f %9.3f %10.3f %10.3f %9.3f\n", name[k - 1], a, b, (a > 0 ? b / a : 0), c, d, (c > 0 ? d / c : 0) } }' "$out/phases"
