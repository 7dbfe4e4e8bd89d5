#!/usr/bin/env bash
# A solver that needs more memory than the job has left ends the run with a
# memory error, the last good state written (docs/robustness.md), not by the
# kernel's OOM killer; one that fits runs on. In a memory cgroup of 600 MB:
#  - MUMPS on the default scene on the ellipse refined 6 times (it estimates
#    1.2 GB at 100% workspace relaxation, 0.73 GB at 20%; the run peaks at
#    0.8 GB resident): a memory error naming MUMPS' estimate;
#  - gmres_amg on the same mesh refined 7 times (it estimates 1.4 GB; 1.0 GB
#    measured, docs/solvers.md): a memory error naming its estimate;
#  - gmres_amg refined 6 times (it estimates 0.36 GB, 0.26 GB measured):
#    runs its steps to the end.
# Without the check the allocations succeed (the kernel overcommits) and the
# process is killed when it touches them.
#   tests/memory_limit.sh SOFTPACK SOURCE_DIR
# Needs a writable cgroup v1 memory controller (root on this kind of
# machine); exits 77 (skipped) where there is none.
set -uo pipefail
softpack=$1 source=$2
fail() { echo "FAIL: $*"; exit 1; }
cg=/sys/fs/cgroup/memory/softpack_memory_limit_$$
mkdir "$cg" 2> /dev/null ||
  { echo "memory_limit: no writable cgroup v1 memory controller here: skipped"; exit 77; }
out=$(mktemp -d)
trap 'rmdir "$cg" 2> /dev/null; rm -rf "$out"' EXIT
echo $((600 * 1024 * 1024)) > "$cg/memory.limit_in_bytes" || fail "cannot set the cgroup's limit"

# run NAME REFINEMENTS SOLVER: the default scene, 2 steps, in the cgroup;
# sets status
run() {
  status=0
  (
    echo "$BASHPID" > "$cg/cgroup.procs" || exit 99
    exec "$softpack" run "$source/inputs/default.yaml" --set mesh.refinements="$2" \
      --set solver.linear="$3" --set time.max_steps=2 --set output.pictures=false --quiet \
      --out "$out/$1"
  ) > "$out/$1.stdout" 2> "$out/$1.stderr" || status=$?
  cat "$out/$1.stderr"
  [ "$status" -ne 99 ] || fail "$1: cannot move the run into the cgroup"
  [ "$status" -ne 137 ] ||
    fail "$1: the run was killed (SIGKILL: the OOM killer) instead of ending with a memory error"
}

# memory_error NAME WHAT: the run NAME ended with a memory error whose
# message says WHAT the solver needs, and wrote its last good state
memory_error() {
  [ "$status" -eq 1 ] || fail "$1: exit status $status, expected 1 (a memory error)"
  grep -q "error (memory)" "$out/$1.stderr" || fail "$1: no memory error on stderr"
  grep -q "MB are left (the memory cgroup's limit)" "$out/$1.stderr" ||
    fail "$1: the message does not say what is left and why"
  grep -q "$2" "$out/$1.stderr" || fail "$1: the message does not say what the solver needs"
  [ -f "$out/$1/fields_000000.vtu" ] || fail "$1: the last good state is not written"
  [ -s "$out/$1/energy.csv" ] || fail "$1: no energy.csv"
}

run mumps 6 mumps
memory_error mumps "workspace relaxation"
run amg_large 7 gmres_amg
memory_error amg_large "multigrid hierarchies and Krylov basis need about"
run amg_fits 6 gmres_amg
[ "$status" -eq 0 ] || fail "amg_fits: exit status $status where its estimate fits"
steps=$(($(wc -l < "$out/amg_fits/energy.csv") - 1))
[ "$steps" -eq 3 ] || fail "amg_fits: $steps rows in energy.csv, expected 3 (t = 0 and 2 steps)"
echo "memory_limit: clean memory errors with the last good state written; a run that fits runs"
