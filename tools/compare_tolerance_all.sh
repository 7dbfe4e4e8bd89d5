#!/usr/bin/env bash
# tools/compare_tolerance.py on the scenes tools/compare_outputs.sh
# compares, cut as it cuts them, on each process count (default 1 and 2;
# on more than one with solver.linear=superlu_dist): for a change that may
# not keep the outputs byte-identical (1e-10 relative in energy,
# masses and centres; Newton iteration counts reported per scene). Both
# binaries run on every scene (no cache). Last line
# "compare_outputs: N run(s) differ beyond the tolerance"; exit status 1 if N > 0.
#   tools/compare_tolerance_all.sh OLD_SOFTPACK NEW_SOFTPACK [NP...] [-- SCENE...]
exec "$(dirname "$0")/compare_outputs.sh" --tolerance "$@"
