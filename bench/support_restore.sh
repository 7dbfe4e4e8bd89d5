#!/usr/bin/env bash
# Where a support change restores each cell's mass (layout.restore, issue
# 29): the interior rule (the baseline: a uniform shift of c_k where c_k
# >= 1/2) against potential (the default: one rise of the chemical
# potential over the whole support, support.c), by bench/support_rule.sh
# on its scenes (or those given).
#   bench/support_restore.sh [SCENE[@T_END][:k=v,k=v...] ...]
exec "$(dirname "$0")/support_rule.sh" layout.restore interior potential "$@"
