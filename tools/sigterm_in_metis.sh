#!/usr/bin/env bash
# The two-process SIGTERM crash inside METIS, made deterministic: a SIGTERM
# that reaches a process while METIS orders a matrix (METIS_NodeND, called
# by SuperLU_DIST's and MUMPS's orderings at every new sparsity pattern:
# the first step, each division, each support change).
#
# Debian's METIS (GKlib) installs its own SIGTERM handler for the length of
# METIS_NodeND (gk_sigtrap: signal(SIGTERM, gk_sigthrow)); a SIGTERM then
# longjmps out of METIS, which returns METIS_ERROR with the ordering
# unwritten; SuperLU_DIST's get_metis_dist does not look at the return
# code and factorises with that garbage column permutation: a segfault in
# sp_colorder, and the stop request never reached softpack (no checkpoint,
# no message). docs/reports/2026-12-02-sigterm-in-metis.md.
#
# The script starts the ctest's two-process run, waits for step K, attaches
# gdb to rank RANK, stops it inside its next METIS_NodeND (after GKlib's
# handler is in place: at libmetis__SetupCtrl), sends it SIGTERM, detaches,
# and checks the test's conditions (status 75, a checkpoint of the last
# step, the message).
#
# usage: tools/sigterm_in_metis.sh [K [RANK]]   (defaults 10 and 1)
# environment: SOFTPACK, SCENE, LAUNCH, RESTART_SET, WORK as in
# tools/sigterm_repeat.sh. Needs gdb and ptrace (root, or
# kernel.yama.ptrace_scope = 0).
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
k=${1:-10}
victim_rank=${2:-1}
sp=$(realpath "${SOFTPACK:-$root/build/softpack}")
scene=$(realpath "${SCENE:-$root/tests/scenes/restart_grow.yaml}")
read -r -a launch <<< "${LAUNCH:-mpiexec -n 2 --allow-run-as-root --oversubscribe}"
work=${WORK:-/tmp/sigterm_in_metis}
sets=()
for kv in ${RESTART_SET-solver.linear=superlu_dist time.t_end=0.005}; do sets+=(--set "$kv"); done
export OMP_NUM_THREADS=1 OMPI_MCA_mpi_yield_when_idle=1
ulimit -c unlimited 2> /dev/null
rm -rf "$work" && mkdir -p "$work" && work=$(realpath "$work") || exit 1
dir=$work/out

(cd "$work" && exec setsid "${launch[@]}" "$sp" run "$scene" --quiet --out "$dir" "${sets[@]}" \
  > "$work/log" 2>&1) &
pid=$!
for ((i = 0; i < 6000; ++i)); do
  [ -f "$dir/energy.csv" ] && [ "$(wc -l < "$dir/energy.csv")" -gt $((k + 1)) ] && break
  kill -0 "$pid" 2> /dev/null || break
  sleep 0.01
done
victim=""
for p in $(pgrep -f -- "^$sp run .*--out $dir( |\$)"); do
  rk=$({ tr '\0' '\n' < "/proc/$p/environ"; } 2> /dev/null | sed -n 's/^OMPI_COMM_WORLD_RANK=//p')
  [ "$rk" = "$victim_rank" ] && victim=$p
done
[ -n "$victim" ] || {
  echo "no process of rank $victim_rank"
  exit 1
}
gdb -p "$victim" -batch -nx -ex "set pagination off" -ex "handle SIGTERM nostop noprint pass" \
  -ex "break libmetis__SetupCtrl" -ex "continue" -ex "bt 8" \
  -ex "shell kill -TERM $victim" -ex "delete" -ex "detach" > "$work/gdb.log" 2>&1
grep -E "^#[0-9]" "$work/gdb.log" | sed 's/^/gdb: /'
at=$(($(wc -l < "$dir/energy.csv") - 2))
echo "SIGTERM to rank $victim_rank (pid $victim) inside METIS_NodeND during step $((at + 1))"
wait "$pid"
status=$?
last=$(tail -n 1 "$dir/energy.csv" | cut -d, -f1)
fail=0
echo "status $status, last step $last"
[ "$status" -eq 75 ] || {
  echo "FAIL: status $status, expected 75"
  fail=1
}
ck=$(printf "%s/checkpoint_%06d.h5" "$dir" "$last")
[ -f "$ck" ] || {
  echo "FAIL: no checkpoint of the last step ($ck)"
  fail=1
}
grep -q "stopped on a signal after step $last" "$work/log" || {
  echo "FAIL: no message"
  fail=1
}
grep -E "Signal:|sp_colorder|stopped on a signal" "$work/log" | head -n 5 | sed 's/^/log: /'
((fail)) || echo "passed"
exit $fail
