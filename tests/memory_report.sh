#!/usr/bin/env bash
# The run summary's memory and message line (docs/parallel.md, "Memory and
# messages per rank"), on the default scene (3 cells on full supports, its
# first 0.0002) on one process and on two:
# - its words, as scripts read them:
#   softpack: memory per rank (MB): mesh M, state S, matrix A, solver L;
#   sent per Newton iteration (MB): X
# - state: 15 doubles per (cell, node) pair (c and mu: 2; the step's
#   buffers: 2 + 1 + 2 + 2 for BDF2 under adaptive control; two past
#   states: 4; the glue's gathered copy: 2), printed to 0.1 MB;
# - one process sends nothing;
# - two: each Newton iteration gathers the state at least once, so the
#   rank that sends most sends at least its rows (half the unknowns or
#   more) in doubles per iteration, and at most four gathers' worth with
#   the Exports of its ghost rows (a residual, a Jacobian, the step's first
#   residual and its last gather per iteration at most).
#   tests/memory_report.sh SOFTPACK SCENE OUTDIR MPIEXEC NUMPROC_FLAG [PREFLAGS...]
set -euo pipefail
bin=$1 scene=$2 out=$3 mpiexec=$4 npflag=$5
shift 5
export OMP_NUM_THREADS=1
rm -rf "$out"
mkdir -p "$out"
common=(--set time.t_end=0.0002 --set output.pictures=false)
"$bin" run "$scene" --out "$out/np1" "${common[@]}" > "$out/np1.log" 2>&1 \
  || { echo "FAIL: the one-process run failed"; tail -5 "$out/np1.log"; exit 1; }
"$mpiexec" "$npflag" 2 "$@" "$bin" run "$scene" --out "$out/np2" "${common[@]}" > "$out/np2.log" 2>&1 \
  || { echo "FAIL: the two-process run failed"; tail -5 "$out/np2.log"; exit 1; }
PYTHONPATH="$(dirname "$0")" python3 - "$out" <<'EOF'
import re, sys
out = sys.argv[1]
from checklib import check, done
pattern = re.compile(r"^softpack: memory per rank \(MB\): mesh ([0-9.]+), state ([0-9.]+), "
                     r"matrix ([0-9.]+), solver ([0-9.]+); sent per Newton iteration \(MB\): "
                     r"([0-9.]+)$")
runs = {}
for np in (1, 2):
    text = open(f"{out}/np{np}.log").read()
    lines = [m.groups() for m in map(pattern.match, text.splitlines()) if m]
    check(len(lines) == 1, f"np {np}: one memory line ({len(lines)})")
    unknowns = int(re.search(r"at most (\d+) unknowns", text).group(1))
    runs[np] = ([float(x) for x in lines[0]] if lines else [0] * 5, unknowns)
(mesh, state, matrix, solver, sent), unknowns = runs[1]
want = 15 * 8 * unknowns / 2 / 2**20
check(abs(state - want) <= 0.05 + 1e-9, f"np 1: state {state} MB, 15 doubles per pair: {want:.3f}")
check(mesh > 0 and matrix > 0, f"np 1: mesh {mesh} MB, matrix {matrix} MB")
check(sent == 0, f"np 1: sent {sent} MB per Newton iteration")
sent2 = runs[2][0][4]
gather = 8 * unknowns / 2 / 2**20
check(gather * (1 - 1e-3) <= sent2 <= 4 * gather,
      f"np 2: sent {sent2} MB per Newton iteration, between one and four gathers of half "
      f"the state ({gather:.3f} MB each)")
done()
EOF
