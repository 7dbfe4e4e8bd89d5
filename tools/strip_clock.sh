#!/usr/bin/env bash
# An energy.csv without its wall-clock columns (seconds, assembly_s,
# factorisation_s, solves_s, supports_s), found by name, on stdout: what
# two runs that must agree byte for byte are compared on
# (tools/compare_outputs.sh, tests/mumps_workspace.sh).
#   tools/strip_clock.sh ENERGY_CSV
exec awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i)
                 if ($i ~ /^(seconds|assembly_s|factorisation_s|solves_s|supports_s)$/) drop[i] = 1 }
     { out = ""; for (i = 1; i <= NF; ++i) if (!(i in drop)) out = out (out == "" ? "" : ",") $i
       print out }' "$1"
