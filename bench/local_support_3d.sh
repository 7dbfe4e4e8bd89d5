#!/usr/bin/env bash
# Full against local supports on the 3D run 5 (inputs/3d/embryo_8.yaml,
# issue 29): the same run with each layout, and per number of cells the
# steps, the simulated time they cover, wall seconds per step (and its
# assembly, factorisation, solves, support changes) and per 0.001 of
# simulated time, unknowns per step and per cell; then the totals (wall
# time, peak memory, largest unknown count) and what the two runs agree on
# (bench/lib.sh compare_runs).
#   bench/local_support_3d.sh [REFINEMENTS] [--set k=v ...]
# REFINEMENTS: mesh.refinements (default 3: 4589 nodes with the buffer).
# Without --set the runs go to the scene's t_end (1 -> 8 cells); e.g.
# --set time.max_steps=20 stops both after 20 steps.
# SOFTPACK=path runs another binary; OUT=dir keeps both runs (dir/full,
# dir/local; otherwise a temporary directory, removed at the end).
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
scene=inputs/3d/embryo_8.yaml
refinements=${1:-3}
shift || true
bin=${SOFTPACK:-build/softpack}
out=${OUT:-$(mktemp -d)}
[ -n "${OUT:-}" ] || trap 'rm -rf "$out"' EXIT
mkdir -p "$out"
export OMP_NUM_THREADS=1
echo "$scene, mesh.refinements=$refinements $*; $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc --all) cores"
for mode in full local; do
  /usr/bin/time -f "%e %M" -o "$out/$mode.time" "$bin" run "$scene" --out "$out/$mode" \
      --set mesh.refinements="$refinements" --set layout.support=$mode "$@" > "$out/$mode.log" 2>&1 ||
    { echo "$mode run failed:"; tail -5 "$out/$mode.log"; exit 1; }
done
echo
echo "| supports | cells | steps | t covered | s/step | assembly | factorisation | solves | supports | s per 0.001 of t | unknowns/step | unknowns/cell | support changes |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for mode in full local; do
  awk -F, -v mode="$mode" 'NR == 1 { for (j = 1; j <= NF; ++j) c[$j] = j; next }
    $1 > 0 { n = $c["n_cells"]; if (!(n in k)) order[++m] = n
             k[n]++; dt[n] += $c["dt"]; sec[n] += $c["seconds"]; as[n] += $c["assembly_s"]
             fa[n] += $c["factorisation_s"]; so[n] += $c["solves_s"]; su[n] += $c["supports_s"]
             u[n] += $c["unknowns"]; ch[n] += $c["support_changed"] }
    END { for (i = 1; i <= m; ++i) { n = order[i]
            printf "| %s | %d | %d | %.3g | %.3f | %.3f | %.3f | %.3f | %.3f | %.1f | %.0f | %.0f | %d |\n",
                   mode, n, k[n], dt[n], sec[n] / k[n], as[n] / k[n], fa[n] / k[n], so[n] / k[n],
                   su[n] / k[n], 1e-3 * sec[n] / dt[n], u[n] / k[n], u[n] / k[n] / n, ch[n] } }' \
    "$out/$mode/energy.csv"
done
echo
echo "| supports | steps | t reached | wall s | peak MB | largest unknowns |"
echo "|---|---|---|---|---|---|"
for mode in full local; do
  read -r wall mem < "$out/$mode.time"
  awk -F, -v mode="$mode" -v wall="$wall" -v mem="$mem" 'NR == 1 { for (j = 1; j <= NF; ++j) c[$j] = j; next }
    { s = $1; t = $2; if ($c["unknowns"] > u) u = $c["unknowns"] }
    END { printf "| %s | %d | %.6g | %.1f | %.0f | %d |\n", mode, s, t, wall, mem / 1024, u }' \
    "$out/$mode/energy.csv"
done
echo
compare_runs "$out/full" "$out/local"
