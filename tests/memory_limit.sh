#!/usr/bin/env bash
# A factorisation larger than the memory left to the job ends the run with a
# memory error, the last good state written (cxx_glue/linear/linear_mumps.cpp,
# docs/robustness.md), not by the kernel's OOM killer: the default scene on
# the ellipse refined 6 times (MUMPS estimates 1.2 GB at 100% workspace
# relaxation, 0.73 GB at 20%; the run peaks at 0.8 GB resident) in a memory
# cgroup of 600 MB. Without the check the allocations succeed (the kernel
# overcommits) and the process is killed when it touches them.
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
status=0
(
  echo "$BASHPID" > "$cg/cgroup.procs" || exit 99
  exec "$softpack" run "$source/inputs/default.yaml" --set mesh.refinements=6 \
    --set time.max_steps=2 --set output.pictures=false --quiet --out "$out/run"
) > "$out/stdout" 2> "$out/stderr" || status=$?
cat "$out/stderr"
[ "$status" -ne 99 ] || fail "cannot move the run into the cgroup"
[ "$status" -ne 137 ] || fail "the run was killed (SIGKILL: the OOM killer) instead of ending with a memory error"
[ "$status" -eq 1 ] || fail "exit status $status, expected 1 (a memory error)"
grep -q "error (memory)" "$out/stderr" || fail "no memory error on stderr"
grep -q "MB are left (the memory cgroup's limit)" "$out/stderr" ||
  fail "the message does not say what is left and why"
grep -q "workspace relaxation" "$out/stderr" || fail "the message does not say what MUMPS needs"
[ -f "$out/run/fields_000000.vtu" ] || fail "the last good state is not written"
[ -s "$out/run/energy.csv" ] || fail "no energy.csv"
echo "memory_limit: a clean memory error, the last good state written"
