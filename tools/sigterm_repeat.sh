#!/usr/bin/env bash
# The SIGTERM case of the ctest mpi_restart_np2 (tests/test_restart.sh),
# repeated: a two-process run of tests/scenes/restart_grow.yaml with the
# ctest's settings, SIGTERM to ONE of its processes (as a scheduler's
# --signal does), and the checks of the test: exit status 75, a checkpoint
# of the last step written, the message "stopped on a signal after step" in
# the log. Issue 27 ("the two-process SIGTERM crash"); docs/restart.md.
#
# usage: tools/sigterm_repeat.sh [N]        (default N = 100)
# environment (defaults in brackets):
#   SOFTPACK   the program                  [build/softpack]
#   SCENE      the scene                    [tests/scenes/restart_grow.yaml]
#   LAUNCH     the launcher                 [mpiexec -n 2 --allow-run-as-root --oversubscribe]
#   RESTART_SET  --set overrides, as the ctest's
#                                           [solver.linear=superlu_dist time.t_end=0.005]
#   WORK       a scratch directory          [/tmp/sigterm_repeat]
#   MODES      which ways to aim the signal [row late time]
#     row:  once energy.csv has the row of a random step k (as the test)
#     late: the same, then a random 0-60 ms more (lands inside the next step:
#           assembly, factorisation, collectives, output, checkpoint writes)
#     time: at a random wall time of the run's stepping (measured by the
#           first, uninterrupted run), counted from the first energy row
#   VICTIMS    which ranks get the signal   [0 1] (one of them at random)
#   NICE       niceness of the runs         [19]
#   KEEP=1     keep the directories of passing runs too
#
# Each run is started with setsid in its own directory with core dumps on
# (ulimit -c unlimited; kernel.core_pattern must name a file, e.g. "core"):
# a crash leaves a core file, and the script prints gdb's backtrace of it.
# Runs are one at a time (two processes each). Printed: one line per run,
# then the counts by status and by check, and the failures' directories.
# Exit status 0 if every run passed.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
n=${1:-100}
sp=$(realpath "${SOFTPACK:-$root/build/softpack}")
scene=$(realpath "${SCENE:-$root/tests/scenes/restart_grow.yaml}")
read -r -a launch <<< "${LAUNCH:-mpiexec -n 2 --allow-run-as-root --oversubscribe}"
work=${WORK:-/tmp/sigterm_repeat}
read -r -a modes <<< "${MODES:-row late time}"
read -r -a victims <<< "${VICTIMS:-0 1}"
nice_level=${NICE:-19}
sets=()
for kv in ${RESTART_SET-solver.linear=superlu_dist time.t_end=0.005}; do sets+=(--set "$kv"); done
export OMP_NUM_THREADS=1 OMPI_MCA_mpi_yield_when_idle=1
ulimit -c unlimited 2> /dev/null || echo "note: core dumps cannot be enabled (ulimit -c)"
case "$(cat /proc/sys/kernel/core_pattern)" in
  '|'*) echo "note: kernel.core_pattern pipes to a program: no core files here" ;;
esac
mkdir -p "$work" || exit 1
work=$(realpath "$work")

now() { date +%s.%N; }

# backtraces DIR: gdb's backtrace of every core file in DIR
backtraces() {
  local core
  for core in "$1"/core*; do
    [ -f "$core" ] || continue
    echo "--- backtrace of $core"
    gdb -batch -nx -ex "info threads" -ex "thread apply all bt" "$sp" "$core" 2>&1 |
      grep -v -E '^\[New LWP|^warning: .*(libthread_db|core file may not match)' | head -n 150
  done
}

# the uninterrupted run: its steps and how long its stepping took
ref="$work/whole"
rm -rf "$ref" && mkdir -p "$ref"
t0=$(now)
(cd "$ref" && nice -n "$nice_level" "${launch[@]}" "$sp" run "$scene" --quiet --out "$ref/out" \
  "${sets[@]}" > "$ref/log" 2>&1)
status=$?
t1=$(now)
if [ "$status" -ne 0 ]; then
  echo "the uninterrupted run failed (status $status): $ref/log"
  backtraces "$ref"
  exit 1
fi
steps=$(($(wc -l < "$ref/out/energy.csv") - 2))
seconds=$(echo "$t1 - $t0" | bc)
echo "uninterrupted: $steps steps in $seconds s; $n runs with SIGTERM to one process"
echo "command: ${launch[*]} $sp run $scene --quiet --out DIR ${sets[*]}"

declare -A by_status=()
runs=0 failures=0 completed=0 crashes=0
failed_dirs=()
for ((r = 1; r <= n; ++r)); do
  dir="$work/run_$r"
  rm -rf "$dir" && mkdir -p "$dir"
  mode=${modes[RANDOM % ${#modes[@]}]}
  victim_rank=${victims[RANDOM % ${#victims[@]}]}
  k=$((1 + RANDOM % (steps - 2)))
  (cd "$dir" && exec setsid nice -n "$nice_level" "${launch[@]}" "$sp" run "$scene" --quiet \
    --out "$dir/out" "${sets[@]}" > "$dir/log" 2>&1) &
  pid=$!
  # the processes of the run (both ranks), by their --out
  pids=()
  for ((i = 0; i < 3000 && ${#pids[@]} < 2; ++i)); do
    mapfile -t pids < <(pgrep -f -- "^$sp run .*--out $dir/out( |\$)")
    kill -0 "$pid" 2> /dev/null || break
    sleep 0.01
  done
  aim=""
  case $mode in
    row | late) # until energy.csv has the row of step k
      for ((i = 0; i < 6000; ++i)); do
        [ -f "$dir/out/energy.csv" ] && [ "$(wc -l < "$dir/out/energy.csv")" -gt $((k + 1)) ] && break
        kill -0 "$pid" 2> /dev/null || break
        sleep 0.01
      done
      aim="row $k"
      if [ "$mode" = late ]; then
        ms=$((RANDOM % 61))
        sleep "$(printf '0.%03d' "$ms")"
        aim="row $k + ${ms} ms"
      fi
      ;;
    time) # a random time of the stepping, after the first energy row
      for ((i = 0; i < 6000; ++i)); do
        [ -s "$dir/out/energy.csv" ] && [ "$(wc -l < "$dir/out/energy.csv")" -gt 1 ] && break
        kill -0 "$pid" 2> /dev/null || break
        sleep 0.01
      done
      delay=$(echo "scale=3; $seconds * 0.95 * $RANDOM / 32768" | bc)
      sleep "$delay"
      aim="${delay} s after step 0"
      ;;
  esac
  victim=""
  for p in "${pids[@]}"; do
    rk=$({ tr '\0' '\n' < "/proc/$p/environ"; } 2> /dev/null | sed -n 's/^OMPI_COMM_WORLD_RANK=//p')
    [ "$rk" = "$victim_rank" ] && victim=$p
  done
  at_signal=$(($(wc -l < "$dir/out/energy.csv" 2> /dev/null || echo 2) - 2))
  if [ -n "$victim" ]; then kill -TERM "$victim" 2> /dev/null || victim=""; fi
  # wait, at most 300 s (a hang is a failure too)
  for ((i = 0; i < 30000; ++i)); do
    kill -0 "$pid" 2> /dev/null || break
    sleep 0.01
  done
  if kill -0 "$pid" 2> /dev/null; then
    echo "run $r: still running 300 s after the signal: killed"
    kill -KILL -- "-$pid" 2> /dev/null
    pkill -KILL -f -- "--out $dir/out( |\$)"
    hung=1
  else hung=0; fi
  wait "$pid"
  status=$?
  ((hung)) && status=hang
  ((++runs))
  by_status[$status]=$((${by_status[$status]:-0} + 1))
  last=$(tail -n 1 "$dir/out/energy.csv" 2> /dev/null | cut -d, -f1)
  [[ "$last" =~ ^[0-9]+$ ]] || last=-1
  why=()
  if [ -z "$victim" ]; then
    # the run ended before the signal could be sent (a late aim)
    if [ "$status" = 0 ] && [ "$last" -eq "$steps" ]; then
      ((++completed))
      echo "run $r: $mode ($aim): the run ended before the signal; status 0"
      [ "${KEEP:-0}" = 1 ] || rm -rf "$dir"
      continue
    fi
    why+=("no process to signal")
  fi
  if [ "$status" = 0 ] && [ "$last" -eq "$steps" ]; then
    # the signal landed in the last step: the run ends there, no checkpoint
    # (nothing is lost); counted apart
    ((++completed))
    echo "run $r: $mode ($aim), rank $victim_rank at step $at_signal: the run completed (status 0)"
    [ "${KEEP:-0}" = 1 ] || rm -rf "$dir"
    continue
  fi
  [ "$status" = 75 ] || why+=("status $status")
  ck=$(printf "%s/out/checkpoint_%06d.h5" "$dir" "$last")
  [ -f "$ck" ] || why+=("no checkpoint of step $last")
  grep -q "stopped on a signal after step $last" "$dir/log" || why+=("no message")
  ls "$dir"/core* > /dev/null 2>&1 && why+=("core file") && ((++crashes))
  if [ ${#why[@]} -eq 0 ]; then
    echo "run $r: $mode ($aim), rank $victim_rank signalled at step $at_signal: stopped after step $last, status 75"
    [ "${KEEP:-0}" = 1 ] || rm -rf "$dir"
  else
    ((++failures))
    failed_dirs+=("$dir")
    echo "run $r: $mode ($aim), rank $victim_rank signalled at step $at_signal: FAIL after step $last: $(
      IFS=,
      echo "${why[*]}")"
    sed 's/^/    log: /' "$dir/log" | grep -v "retried with dt" | tail -n 30
    backtraces "$dir"
  fi
done

echo
echo "runs: $runs; passed: $((runs - failures - completed)); completed before the signal took effect: $completed; failed: $failures (with a core file: $crashes)"
echo -n "exit statuses:"
for s in "${!by_status[@]}"; do echo -n " $s x${by_status[$s]}"; done
echo
for d in "${failed_dirs[@]}"; do echo "failed: $d"; done
exit $((failures > 0))
