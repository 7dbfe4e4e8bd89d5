#!/usr/bin/env bash
# Continued runs equal uninterrupted ones (docs/restart.md), on
# tests/scenes/restart_grow.yaml (growth, mass divisions 1 -> 2 -> 4, local
# supports, the shape term, adaptive BDF2, checkpoints every 4 steps):
# - a run killed with SIGKILL at a random step and resumed from its newest
#   checkpoint (--resume), and one stopped by SIGTERM to one of its
#   processes (exit status 75, also through mpirun; a checkpoint at the
#   step it stopped) and resumed, write energy.csv,
#   cells.csv, divisions.csv, contacts.csv and fields.pvd byte for byte as the
#   uninterrupted run; so does one asked to stop in the middle of a step
#   (SOFTPACK_FAULT=interrupt:...: the step is dropped, status 75);
# - SIGKILLs at random times with a checkpoint every step (so some land
#   inside a checkpoint write): the logs hold whole lines and the newest
#   checkpoint is readable (the resumed run again equals the whole one);
# - with a launcher (mpirun -np 2 ...): the same on two processes, and a
#   checkpoint of one process resumed on two, one of two resumed on one
#   and on three: the energies agree to 1e-9 relative with the whole run's
#   (Newton's tolerance is 1e-8 on the residual; the partition changes the
#   rounding, not the steps);
# - a continued run that changes the physics (--set model.kappa=...), and
#   one from a truncated or a foreign checkpoint, are refused: exit 2, a
#   message naming the key or the file, nothing in the directory changed.
#
# MUMPS on several processes is not bitwise reproducible even between two
# uninterrupted runs (its parallel assembly order varies); the ctest on two
# processes sets RESTART_SET=solver.linear=superlu_dist, which is.
#
# usage: [RESTART_SET="key=value ..."] test_restart.sh SOFTPACK SCENE WORKDIR [LAUNCHER...]
set -uo pipefail
sp=$1 scene=$2 work=$3
shift 3
launch=("$@")
sets=()
for kv in ${RESTART_SET:-}; do sets+=(--set "$kv"); done
export OMP_NUM_THREADS=1
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
rm -rf "$work" && mkdir -p "$work" || exit 1

run() { # DIR [ARGS...]: a run in the foreground, its status
  local dir=$1
  shift
  "${launch[@]}" "$sp" run "$scene" --quiet --out "$dir" "${sets[@]}" "$@" >> "$dir.log" 2>&1
}

# start DIR [ARGS...]: a run in the background in its own process group
start() {
  local dir=$1
  shift
  setsid "${launch[@]}" "$sp" run "$scene" --quiet --out "$dir" "${sets[@]}" "$@" \
    >> "$dir.log" 2>&1 &
  pid=$!
}

# kill_run DIR: SIGKILL the run writing DIR, launcher and processes (Open
# MPI puts each process in a process group of its own)
kill_run() {
  local i
  kill -KILL -- "-$pid" 2>/dev/null
  pkill -KILL -f -- "--out $1( |\$)" 2>/dev/null
  wait "$pid" 2>/dev/null
  for ((i = 0; i < 500; ++i)); do
    pgrep -f -- "--out $1( |\$)" > /dev/null || return 0
    sleep 0.01
  done
  fail "the processes of $1 outlived SIGKILL"
}

# wait_rows DIR N: until energy.csv has a row of step >= N or the run ended
wait_rows() {
  local i
  for ((i = 0; i < 2000; ++i)); do
    [ -f "$1/energy.csv" ] && [ "$(wc -l < "$1/energy.csv")" -gt $(($2 + 1)) ] && return 0
    kill -0 "$pid" 2>/dev/null || return 0
    sleep 0.01
  done
}

same_as_whole() { # DIR LABEL
  local f
  for f in energy.csv cells.csv divisions.csv contacts.csv fields.pvd; do
    cmp -s "$work/whole/$f" "$1/$f" || fail "$2: $f differs from the uninterrupted run's"
  done
}

whole_lines() { # DIR LABEL: every log ends with a newline
  local f
  for f in energy.csv cells.csv divisions.csv contacts.csv; do
    [ ! -s "$1/$f" ] || [ "$(tail -c 1 "$1/$f" | od -An -c | tr -d ' ')" = '\n' ] ||
      fail "$2: $f ends inside a line"
  done
}

# the uninterrupted run
run "$work/whole" || fail "the uninterrupted run failed (status $?)"
steps=$(($(wc -l < "$work/whole/energy.csv") - 2))
echo "uninterrupted: $steps steps, $(($(wc -l < "$work/whole/divisions.csv") - 1)) divisions"
[ "$steps" -ge 20 ] || fail "only $steps steps"

# SIGKILL at a random step (after the first checkpoint at step 4), resumed
k=$((6 + RANDOM % (steps / 2 - 6)))
start "$work/killed"
wait_rows "$work/killed" "$k"
kill_run "$work/killed"
echo "killed after step $(tail -n 1 "$work/killed/energy.csv" | cut -d, -f1) (aimed at $k)"
whole_lines "$work/killed" "SIGKILL"
run "$work/killed" --resume "$work/killed" || fail "--resume after SIGKILL: status $?"
same_as_whole "$work/killed" "SIGKILL at step $k, resumed"

# SIGTERM at a random step of the first half (a signal forwarded by mpirun
# on a busy machine may take a few steps to land): a checkpoint at the
# step it stopped, status 75
k=$((6 + RANDOM % (steps / 2 - 6)))
start "$work/term"
wait_rows "$work/term" "$k"
# to one process of the run, as a scheduler's signal reaches the tasks
# (not to mpirun, which would tear the job down and may drop its output):
# the processes agree on the stop
victim=$(pgrep -f -- "^$sp run .*--out $work/term( |\$)" | tail -n 1)
kill -TERM "$victim"
wait "$pid"
status=$?
last=$(tail -n 1 "$work/term/energy.csv" | cut -d, -f1)
echo "SIGTERM after step $last (aimed at $k): status $status"
[ "$status" -eq 75 ] || fail "SIGTERM: status $status, expected 75"
[ "$last" -lt "$steps" ] || fail "SIGTERM: the run did not stop early"
ck=$(printf "%s/term/checkpoint_%06d.h5" "$work" "$last")
[ -f "$ck" ] || fail "SIGTERM: no checkpoint of the last step ($ck)"
grep -q "stopped on a signal after step $last" "$work/term.log" || fail "SIGTERM: no message"
run "$work/term" --resume "$work/term" || fail "--resume after SIGTERM: status $?"
same_as_whole "$work/term" "SIGTERM at step $k, resumed"

# A stop requested during a step (SOFTPACK_FAULT=interrupt:RANK:STEP:ATTEMPT:
# as a SIGTERM landing after the first Newton iteration of that attempt; a
# 3D step can outlast a scheduler's grace before SIGKILL): the step is
# dropped, a checkpoint of the step before, status 75, and the resumed run
# equals the whole one. Once in the first attempt of a random step, once in
# the second attempt of the first step that was retried, if one was (so the
# controller's state goes back to the step's start, not only the carried
# factorisation); on the
# last process with a launcher (the stop agreed by the others).
rank=0
[ ${#launch[@]} -gt 0 ] && rank=1
retried=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
                   $1 >= 6 && $(c["failed_attempts"]) > 0 { print $1; exit }' "$work/whole/energy.csv")
specs=("$((6 + RANDOM % (steps / 2 - 6))):1")
# (the 2D scene retries steps; a scene without a retried step, as the 3D
# one, has the first case only)
if [ -n "$retried" ]; then specs+=("$retried:2"); else echo "no retried step: one case"; fi
for spec in "${specs[@]}"; do
  k=${spec%%:*}
  d=$work/interrupt_${spec/:/_}
  (export SOFTPACK_FAULT="interrupt:$rank:$spec"; run "$d")
  status=$?
  last=$(tail -n 1 "$d/energy.csv" | cut -d, -f1)
  echo "a stop during step $k (attempt ${spec##*:}): status $status, last step $last"
  [ "$status" -eq 75 ] || fail "interrupt $spec: status $status, expected 75"
  [ "$last" = $((k - 1)) ] || fail "interrupt $spec: last step $last, expected $((k - 1))"
  ck=$(printf "%s/checkpoint_%06d.h5" "$d" "$((k - 1))")
  [ -f "$ck" ] || fail "interrupt $spec: no checkpoint of step $((k - 1)) ($ck)"
  grep -q "a stop was requested during step $k: the step is dropped" "$d.log" ||
    fail "interrupt $spec: no message"
  run "$d" --resume "$d" || fail "--resume after interrupt $spec: status $?"
  same_as_whole "$d" "a stop during step $k (attempt ${spec##*:}), resumed"
done

# SIGKILLs at random times, a checkpoint every step: some land in a write
# (compared with an uninterrupted run with a checkpoint every step too: a
# checkpoint makes the next factorisation start afresh)
run "$work/whole_often" --set output.checkpoint_every=1 || fail "whole_often: status $?"
start "$work/often" --set output.checkpoint_every=1
last=0
for round in 1 2 3; do
  wait_rows "$work/often" $((last + 1 + RANDOM % 4))
  sleep "0.0$((RANDOM % 10))"
  kill_run "$work/often"
  last=$(tail -n 1 "$work/often/energy.csv" 2>/dev/null | cut -d, -f1)
  [[ "$last" =~ ^[0-9]+$ ]] || last=0
  # a kill inside a step's write may tear its last line (the kernel stops a
  # write of several pages at a fatal signal): resume drops it, and the
  # logs after the rounds must equal the uninterrupted run's (below)
  for f in energy.csv cells.csv divisions.csv contacts.csv; do
    [ ! -s "$work/often/$f" ] || [ "$(tail -c 1 "$work/often/$f" | od -An -c | tr -d ' ')" = '\n' ] ||
      echo "round $round: $f ends inside a line (a kill inside its write): resume drops it"
  done
  tmp=$(ls "$work/often"/*.tmp 2>/dev/null | wc -l)
  echo "round $round: killed after step $last, $tmp temporary checkpoint(s) left"
  if [ "$(ls "$work/often"/checkpoint_*.h5 2>/dev/null | wc -l)" -gt 0 ]; then
    start "$work/often" --set output.checkpoint_every=1 --resume "$work/often"
  else # killed before its first checkpoint: start again
    start "$work/often" --set output.checkpoint_every=1
  fi
done
wait "$pid"
run "$work/often" --set output.checkpoint_every=1 --resume "$work/often" ||
  fail "--resume after the SIGKILL rounds: status $?"
for f in energy.csv cells.csv divisions.csv contacts.csv fields.pvd; do
  cmp -s "$work/whole_often/$f" "$work/often/$f" || fail "SIGKILL rounds: $f differs"
done

# several processes: a checkpoint of one process resumed on them, and one
# of the launcher's processes resumed on one process and on one more
# process than the launcher's (mpiexec -n P ...: its third word)
if [ ${#launch[@]} -gt 0 ]; then
  energies_agree() { # DIR LABEL: the same steps as the whole run, energies to 1e-9 relative
    awk -F, -v label="$2" 'NR == FNR { e[$1] = $6; t[$1] = $2; n = FNR; next }
             FNR > 1 { m = FNR; d = ($6 - e[$1]) / e[$1]; if (d < 0) d = -d; if (d > worst) worst = d
                       dt = $2 - t[$1]; if (dt < 0) dt = -dt; if (dt > tw) tw = dt }
             END { printf "%s: %d and %d rows, largest relative energy difference %.2e, '\
'largest time difference %.2e\n", label, n, m, worst, tw
                   exit !(n == m && worst <= 1e-9 && tw <= 1e-12) }' \
      "$work/whole/energy.csv" "$1/energy.csv" ||
      fail "$2: the energies differ by more than 1e-9"
  }
  mkdir -p "$work/serial"
  "$sp" run "$scene" --quiet --out "$work/serial" "${sets[@]}" --set output.checkpoint_keep=100 \
    > "$work/serial.log" 2>&1 || fail "the one-process run failed"
  ck=$(ls "$work/serial"/checkpoint_*.h5 | sed -n 3p)
  run "$work/serial" --restart "$ck" --set output.checkpoint_keep=100 ||
    fail "a one-process checkpoint resumed on ${launch[*]}: status $?"
  energies_agree "$work/serial" "one process resumed on ${launch[*]}"
  if [[ ${#launch[@]} -ge 3 && ${launch[2]} =~ ^[0-9]+$ ]]; then
    run "$work/ranks" --set output.checkpoint_keep=100 || fail "the run on ${launch[*]} failed"
    ck_ranks=$(basename "$(ls "$work/ranks"/checkpoint_*.h5 | sed -n 3p)")
    cp -r "$work/ranks" "$work/ranks_on_1"
    "$sp" run "$scene" --quiet --out "$work/ranks_on_1" "${sets[@]}" \
      --restart "$work/ranks_on_1/$ck_ranks" --set output.checkpoint_keep=100 \
      > "$work/ranks_on_1.log" 2>&1 || fail "a checkpoint of ${launch[*]} resumed on one process: status $?"
    energies_agree "$work/ranks_on_1" "${launch[2]} processes resumed on 1"
    more=("${launch[@]}")
    more[2]=$((launch[2] + 1))
    cp -r "$work/ranks" "$work/ranks_on_more"
    "${more[@]}" "$sp" run "$scene" --quiet --out "$work/ranks_on_more" "${sets[@]}" \
      --restart "$work/ranks_on_more/$ck_ranks" --set output.checkpoint_keep=100 \
      > "$work/ranks_on_more.log" 2>&1 ||
      fail "a checkpoint of ${launch[*]} resumed on ${more[*]}: status $?"
    energies_agree "$work/ranks_on_more" "${launch[2]} processes resumed on ${more[2]}"
  fi
fi

# a continued run may not change the physics: refused, nothing changed
before=$(ls -l --time-style=+%s.%N "$work/whole" | md5sum)
run "$work/whole" --resume "$work/whole" --set model.kappa=2e-3
status=$?
[ "$status" -eq 2 ] || fail "a changed model.kappa: status $status, expected 2"
grep -q "model.kappa differs from the checkpoint's scene" "$work/whole.log" ||
  fail "a changed model.kappa: no message naming the key"
[ "$(ls -l --time-style=+%s.%N "$work/whole" | md5sum)" = "$before" ] ||
  fail "a refused restart changed the output directory"

# a damaged or foreign checkpoint: refused, nothing changed
ck=$(ls "$work/whole"/checkpoint_*.h5 | tail -n 1)
head -c 5000 "$ck" > "$work/truncated.h5"
echo "not a checkpoint" > "$work/foreign.h5"
for bad in truncated foreign; do
  before=$(ls -l --time-style=+%s.%N "$work/whole" | md5sum)
  run "$work/whole" --restart "$work/$bad.h5"
  status=$?
  [ "$status" -eq 2 ] || fail "a $bad checkpoint: status $status, expected 2"
  grep -q "checkpoint '$work/$bad.h5'" "$work/whole.log" || fail "a $bad checkpoint: no message"
  [ "$(ls -l --time-style=+%s.%N "$work/whole" | md5sum)" = "$before" ] ||
    fail "a $bad checkpoint changed the output directory"
done

[ "$failures" -eq 0 ] && echo "all checks passed"
exit $((failures > 0))
