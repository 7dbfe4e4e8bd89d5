#!/usr/bin/env bash
# Where the direct solvers stop in 3D: the paper's run 5 in 3D
# (inputs/3d/embryo_8.yaml) cut to STEPS steps, for each case r:cells
# (mesh.refinements r; cells 1: the scene's zygote, 8: eight spheres of
# radius 0.09 at (+-0.11, +-0.095, +-0.095), the scene's cells replaced
# through bench/lib.sh's scene_without_cells), with each linear solver
# (superlu_dist on NP_DIST processes; a solver written NAME@P runs on P
# processes, e.g. gmres_cells@2), one run at a time. Each run has a
# memory cap, MEM_GB of address space per process (ulimit -v), and a time
# cap, TIME_S seconds of CPU per process (ulimit -t: on a shared machine
# the wall time measures the load as much as the solver), with WALL_S
# seconds of wall time (timeout) as a safety net. Per run: the first
# step's unknowns and the run's largest; the first step's factorisations,
# wall seconds per factorisation (energy.csv's factorisation_s over its
# factorisations; gmres_ilu: the ILU's set-up) and its CPU seconds
# estimated as that times the run's CPU / wall share, the first step's
# solves; the steps, Newton and GMRES iterations; the run's wall and CPU
# seconds (user + sys of all its processes) and peak resident memory (of
# the largest process: a rank's for superlu_dist); and the result: ok,
# "stopped: memory", "stopped: CPU time", "stopped: wall time", or
# "failed" with the program's last message (a stopped run still shows its
# first step if it finished it). A solver that stopped is not run in the
# later cases (so give them by size). At the end, the growth exponent p
# of the factorisation's time (t ~ n^p, n the first step's unknowns) and
# of the peak memory between the first two refinements run for each
# solver and cell count.
#   nice -n 10 bench/solvers_3d.sh [CASE ...]
# Defaults: cases 3:1 3:8 4:1 4:8; STEPS=2, MEM_GB=8, TIME_S=300,
# WALL_S=3 x TIME_S,
# SOLVERS="superlu mumps klu superlu_dist gmres_ilu gmres_cells",
# NP_DIST=2; SOFTPACK=path runs another binary; OUT=dir keeps the runs
# (otherwise a temporary directory, removed at the end). docs/3d.md,
# "Direct solvers in 3D: where they stop", has a table and what it says.
set -uo pipefail
cd "$(dirname "$0")/.."
. bench/lib.sh
scene=inputs/3d/embryo_8.yaml
cases=("$@")
[ ${#cases[@]} -eq 0 ] && cases=(3:1 3:8 4:1 4:8)
steps=${STEPS:-2} mem_gb=${MEM_GB:-8} time_s=${TIME_S:-300} np_dist=${NP_DIST:-2}
wall_s=${WALL_S:-$((3 * time_s))}
read -ra solvers <<< "${SOLVERS:-superlu mumps klu superlu_dist gmres_ilu gmres_cells}"
bin=${SOFTPACK:-build/softpack}
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
export OMP_NUM_THREADS=1

scene_without_cells "$scene" > "$out/embryo_8_cells.yaml"
{
  echo "cells:"
  for x in -0.11 0.11; do for y in -0.095 0.095; do for z in -0.095 0.095; do
    echo "  - {x: $x, y: $y, z: $z, radius: 0.09}"
  done; done; done
} >> "$out/embryo_8_cells.yaml"

echo "$scene, time.max_steps=$steps; caps per process ${mem_gb} GB of address space and ${time_s} s of CPU, ${wall_s} s wall per run"
echo "$(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc --all) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
rows=$out/rows.txt
: > "$rows"
declare -A stopped
for case in "${cases[@]}"; do
  r=${case%:*} n=${case#*:}
  case $n in
    1) file=$scene ;;
    8) file=$out/embryo_8_cells.yaml ;;
    *) echo "case $case: cells must be 1 or 8" >&2; exit 2 ;;
  esac
  for s in "${solvers[@]}"; do
    run=r${r}_c${n}_$s
    if [ -n "${stopped[$s]:-}" ]; then
      echo "$r $n $s skipped: stopped at ${stopped[$s]}" >> "$rows"
      echo "$run: skipped (stopped at ${stopped[$s]})"
      continue
    fi
    linear=${s%@*} np=1
    [ "$linear" = superlu_dist ] && np=$np_dist
    [ "$s" != "$linear" ] && np=${s#*@} && run=r${r}_c${n}_${linear}_np$np
    launch=()
    [ "$np" -gt 1 ] && launch=(mpirun --allow-run-as-root --oversubscribe -np "$np")
    rm -f "$out/$run.time"
    (
      ulimit -v $((mem_gb * 1024 * 1024)) -t "$time_s" -c 0 # (SIGKILL at the CPU cap)
      exec timeout -k 10 "$wall_s" "${launch[@]}" /usr/bin/time -a -o "$out/$run.time" \
        -f "%e %U %S %M" "$bin" run "$file" --out "$out/$run" \
        --set mesh.refinements="$r" --set time.max_steps="$steps" --set solver.linear="$linear" \
        --set output.pictures=false
    ) > "$out/$run.log" 2>&1
    status=$?
    # one line per process: wall the longest, CPU the sum (and the largest
    # process's, for the cap), peak the largest
    read -r wall user sys peak cpu_max < <(awk 'NF == 4 && $1 ~ /^[0-9.]+$/ {
        if ($1 > w) w = $1; u += $2; s += $3; if ($4 > m) m = $4; if ($2 + $3 > c) c = $2 + $3 }
      END { if (NR) print w, u, s, m, c }' "$out/$run.time" 2> /dev/null)
    if [ "$status" -eq 124 ]; then
      result="stopped: wall time > ${wall_s} s"
    elif [ "$status" -ne 0 ] && grep -qE 'signal (9|24)$' "$out/$run.time" &&
         awk -v cap="$time_s" '{ exit !($1 >= 0.95 * cap) }' <<< "${cpu_max:-0}"; then
      result="stopped: CPU time > ${time_s} s"
    elif [ "$status" -ne 0 ] && grep -qiE 'memory|alloc' "$out/$run.log"; then
      # MUMPS says what it asked for (linear_mumps.cpp); else the last such line
      asked=$(grep -o 'INFOG(1) = -13, INFOG(2) = -*[0-9]*): out of memory (it asked for [^)]*)' \
        "$out/$run.log" | tail -1 | sed 's/): out of memory (/: /; s/)$//')
      result="stopped: memory > ${mem_gb} GB ($([ -n "$asked" ] && echo "MUMPS $asked" ||
        grep -iE 'memory|alloc' "$out/$run.log" | tail -1 |
        sed 's/.*(time.max_retries[^)]*): //' | cut -c1-100))"
    elif [ "$status" -ne 0 ]; then
      result="failed: exit $status ($(grep -v '^---' "$out/$run.log" | tail -1 | cut -c1-100))"
    else
      result=ok
    fi
    [ "$result" = ok ] || stopped[$s]="$r:$n"
    # energy.csv: step 1's unknowns, factorisations, their seconds and the
    # solves'; over the run the largest unknowns, steps and iterations
    summary=$(awk -F, 'NR == 1 { for (j = 1; j <= NF; ++j) c[$j] = j; next }
      $1 == 1 { u1 = $c["unknowns"]; f1 = $c["factorisations"]; fs1 = $c["factorisation_s"]; ss1 = $c["solves_s"] }
      $1 > 0 { steps++; its += $c["newton_its"]; lin += $c["linear_its"]
               if ($c["unknowns"] > umax) umax = $c["unknowns"] }
      END { if (steps) printf "%d %d %d %.3f %.3f %d %d %d", u1, umax, f1, f1 ? fs1 / f1 : 0, ss1, steps, its, lin
            else printf "- - - - - 0 - -" }' "$out/$run/energy.csv" 2> /dev/null || echo "- - - - - 0 - -")
    echo "$r $n $s $summary ${wall:--} ${user:-0} ${sys:-0} ${peak:-0} $result" >> "$rows"
    echo "$run: $summary; ${wall:-?} s wall, ${user:-?} + ${sys:-?} s CPU, ${peak:-?} kB peak; $result"
  done
done

echo
echo "load at the end $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| refinements | cells | solver | unknowns (step 1) | largest | step 1: factorisations | s each (wall) | s each (CPU, est.) | step 1 solves s | steps | Newton its | GMRES its | run wall s | run CPU s | peak MB | result |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
# rows: r cells solver u1 umax f1 s_each solves1 steps its gmres wall user sys peak result...
awk '$4 == "skipped:" { printf "| %s | %s | %s | | | | | | | | | | | | | %s |\n", $1, $2, $3, substr($0, index($0, "skipped")); next }
  { cpu = $13 + $14; est = ($7 != "-" && $12 > 0) ? sprintf("%.2f", $7 * cpu / $12) : "-"
    printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %.1f | %.0f | %s |\n",
           $1, $2, $3, $4, $5, $6, $7, est, $8, $9, $10, $11, $12, cpu, $15 / 1024, substr($0, index($0, $16)) }' "$rows"
echo
echo "growth between the first two refinements run (t ~ n^p, n the first step's unknowns; CPU: estimated as above):"
awk '$16 == "ok" { key = $3 ", " $2 " cell(s)"; cpu = $13 + $14
      if (!(key in r0)) { r0[key] = $1; n0[key] = $4; w0[key] = $7; c0[key] = $7 * cpu / $12; m0[key] = $15; order[++k] = key }
      else if (!(key in r1)) { r1[key] = $1; n1[key] = $4; w1[key] = $7; c1[key] = $7 * cpu / $12; m1[key] = $15 } }
  END { for (i = 1; i <= k; ++i) { key = order[i]; if (!(key in r1)) continue
          l = log(n1[key] / n0[key])
          printf "  %s: r = %s -> %s, unknowns %d -> %d (x%.2f): factorisation %.2f -> %.2f s wall (p = %.2f), %.2f -> %.2f s CPU (p = %.2f); peak memory p = %.2f\n",
                 key, r0[key], r1[key], n0[key], n1[key], n1[key] / n0[key], w0[key], w1[key],
                 log(w1[key] / w0[key]) / l, c0[key], c1[key], log(c1[key] / c0[key]) / l, log(m1[key] / m0[key]) / l } }' "$rows"
[ -n "${OUT:-}" ] || rm -rf "$out"
