#!/usr/bin/env bash
# The linear solvers side by side: MUMPS (the 2D default), gmres_cells
# (GMRES on the cells' blocks factored by MUMPS, the 3D default below
# 15,000 mesh nodes) and gmres_amg (GMRES with the Cahn-Hilliard block
# preconditioner of AMG V-cycles, no factorisation, the 3D default from
# there), each case run once per solver and process
# count, one run at a time, every run the same fixed steps (backward
# Euler at a fixed dt, no growth of dt) so that they solve the same
# systems. Per run: the largest unknowns, the Newton iterations, the GMRES
# iterations per Newton iteration, the seconds per Newton iteration
# (assembly + factorisation or set-up + solves, over the Newton
# iterations), the peak resident memory of rank 0 (GNU time) and that per
# unknown on rank 0 (its share: unknowns / processes).
#   nice -n 10 bench/solvers.sh [CASE ...]
# CASE is one of
#   h:R       the default scene (3 cells) at mesh.refinements R, dt 1e-5
#   dt:DT     the default scene at refinements 6, time.dt DT
#   cells:N   N just-born cells packed in the aggregate's ellipse
#             (bench/lib.sh packed_scene; local supports), dt 2e-5
#   3d:R      the 3D run 5's ellipsoid at refinements R with 8 spheres
#             (as bench/solvers_3d.sh), dt 1e-5
# Defaults: cases h:5 h:6 h:7 dt:1e-7 dt:1e-6 dt:1e-5 dt:1e-4 cells:16
# cells:64 3d:3; STEPS=3 steps per run; SOLVERS="mumps gmres_cells
# gmres_amg"; NPS="1 2" (process counts); SOFTPACK=path runs another
# binary; OUT=dir keeps the runs. docs/solvers.md has the tables.
set -uo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
cases=("$@")
[ ${#cases[@]} -eq 0 ] && cases=(h:5 h:6 h:7 dt:1e-7 dt:1e-6 dt:1e-5 dt:1e-4 cells:16 cells:64 3d:3)
steps=${STEPS:-3}
read -ra solvers <<< "${SOLVERS:-mumps gmres_cells gmres_amg}"
read -ra nps <<< "${NPS:-1 2}"
bin=${SOFTPACK:-build/softpack}
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
[ -n "${OUT:-}" ] || trap 'rm -rf "$out"' EXIT
export OMP_NUM_THREADS=1

{
  scene_without_cells inputs/3d/embryo_8.yaml
  echo "cells:"
  for x in -0.11 0.11; do for y in -0.095 0.095; do for z in -0.095 0.095; do
    echo "  - {x: $x, y: $y, z: $z, radius: 0.09}"
  done; done; done
} > "$out/embryo_8_spheres.yaml"

echo "bench/solvers.sh ${cases[*]}; STEPS=$steps, solvers ${solvers[*]}, processes ${nps[*]}"
echo "$(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc --all) cores, $(awk '/MemTotal/ { printf "%.0f GB", $2 / 1048576 }' /proc/meminfo), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| case | solver | processes | unknowns | Newton its | GMRES its / Newton | s / Newton | peak MB (rank 0) | kB / unknown (rank 0) |"
echo "|---|---|---|---|---|---|---|---|---|"
for spec in "${cases[@]}"; do
  kind=${spec%%:*} value=${spec#*:}
  fixed=(--set time.control=fixed --set time.scheme=be --set time.grow=1
         --set output.every=1000000 --set output.pictures=false)
  case $kind in
    h) scene=inputs/default.yaml
       sets=(--set mesh.refinements="$value" --set time.dt=1e-5) ;;
    dt) scene=inputs/default.yaml
        sets=(--set mesh.refinements=6 --set time.dt="$value") ;;
    cells) scene=$out/packed_$value.yaml
           packed_scene "$value" "$scene" || continue
           sets=(--set division.criterion=none --set source.rate=0 --set time.dt=2e-5) ;;
    3d) scene=$out/embryo_8_spheres.yaml
        sets=(--set mesh.refinements="$value" --set time.dt=1e-5) ;;
    *) echo "unknown case $spec" >&2; exit 2 ;;
  esac
  dt=$(printf '%s\n' "${sets[@]}" | sed -n 's/^time.dt=//p')
  t_end=$(awk -v n="$steps" -v dt="$dt" 'BEGIN { printf "%.17g", n * dt * 1.0000001 }')
  for np in "${nps[@]}"; do
    for solver in "${solvers[@]}"; do
      run=$out/${kind}_${value}_${solver}_$np
      launch=()
      [ "$np" -gt 1 ] && launch=(mpirun --allow-run-as-root -np "$np")
      /usr/bin/time -f "peak %M kB" -o "$run.time" "${launch[@]}" "$bin" run "$scene" --out "$run" \
        "${fixed[@]}" "${sets[@]}" --set time.t_end="$t_end" --set time.max_steps="$steps" \
        --set solver.linear="$solver" > "$run.log" 2>&1
      status=$?
      awk -v c="$spec" -v s="$solver" -v np="$np" -v st="$status" '
        /at most [0-9]+ unknowns/ { for (i = 1; i <= NF; ++i) if ($i == "most") n = $(i + 1) }
        / Newton iterations \(/ {
          for (i = 1; i <= NF; ++i) {
            if ($(i + 1) == "Newton" && $(i + 2) ~ /^iterations/) newton = $i
            if ($(i + 1) == "GMRES") gmres = $i
            if ($(i + 1) == "s" && $(i + 2) == "(assembly") { a = $(i + 3); f = $(i + 5); v = $(i + 7) }
          }
          sub(/,/, "", a); sub(/,/, "", f); sub(/\)[;,]?/, "", v)
        }
        /^peak/ { peak = $2 }
        END {
          if (st != 0 || newton == "") { printf "| %s | %s | %d | %s | failed (exit %d) | | | | |\n", c, s, np, n, st; exit }
          printf "| %s | %s | %d | %d | %d | %.1f | %.3f | %.0f | %.2f |\n", c, s, np, n, newton,
                 gmres / newton, (a + f + v) / newton, peak / 1024, peak / (n / np)
        }' "$run.log" "$run.time"
      [ "$status" -eq 0 ] || tail -2 "$run.log" | sed 's/^/    /' >&2
    done
  done
done
