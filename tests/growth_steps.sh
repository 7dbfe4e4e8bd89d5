#!/usr/bin/env bash
# Issue 28's step-count criterion on its reproducer (tests/scenes/growth_two.yaml:
# two touching cells growing, adaptive BDF2 at the defaults): with local
# supports at the default margin the run may take at most 20% more accepted
# steps than with full supports, and at most 10 rejected attempts (support
# changes must not make the controller crawl), and both runs reach t_end.
#   tests/growth_steps.sh SOFTPACK SCENE OUTDIR
set -euo pipefail
bin=$1 scene=$2 out=$3
export OMP_NUM_THREADS=1
rm -rf "$out"
mkdir -p "$out"
count() { # DIR: "accepted rejected t changes" from energy.csv
  awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
           $(col["step"]) == 0 { next }
           { ++n; rej += $(col["failed_attempts"]); t = $(col["t"]); chg += $(col["support_changed"]) }
           END { print n, rej, t, chg }' "$1/energy.csv"
}
for v in full local; do
  "$bin" run "$scene" --out "$out/$v" --quiet --set layout.support="$v" > "$out/$v.log" 2>&1 \
    || { echo "FAIL: the $v run failed:"; tail -5 "$out/$v.log"; exit 1; }
done
read -r nf rf tf cf < <(count "$out/full")
read -r nl rl tl cl < <(count "$out/local")
echo "full: $nf accepted, $rf rejected, t = $tf; local: $nl accepted, $rl rejected, $cl support changes, t = $tl"
fail=0
awk -v a="$tf" -v b="$tl" 'BEGIN { exit !(a == 0.003 && b == 0.003) }' \
  || { echo "FAIL: a run stopped before t_end 0.003"; fail=1; }
[ "$cf" -eq 0 ] || { echo "FAIL: full supports changed $cf times"; fail=1; }
[ "$cl" -ge 1 ] || { echo "FAIL: the local run had no support change: it tests nothing"; fail=1; }
awk -v f="$nf" -v l="$nl" 'BEGIN { exit !(l <= 1.2 * f) }' \
  || { echo "FAIL: local supports took $nl accepted steps, more than 1.2 x full's $nf"; fail=1; }
[ "$rl" -le 10 ] || { echo "FAIL: local supports had $rl rejected attempts (at most 10)"; fail=1; }
[ $fail -eq 0 ] && echo "PASS"
exit $fail
