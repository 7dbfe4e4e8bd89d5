#!/usr/bin/env python3
"""How dt recovers after each division of a run (the controller's restart
at a division: docs/time-stepping.md), from the run's energy.csv and
divisions.csv:

    bench/division_recovery.py OUT_DIR [GOAL_STEPS]

Per division (at the end of step s, whose dt is the dt before it): the dt
of the first step after it and its ratio to the dt before; how many steps
until dt is back to half the dt before (GOAL_STEPS, default 6, is the
goal: the count is marked when above it); the failed attempts in the steps
from the division until then (or until the next division); then the
largest of each and how many divisions met the goal. Several divisions at
one step count once. Needs only python3.
"""
import csv
import os
import sys


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    goal = int(sys.argv[2]) if len(sys.argv) > 2 else 6
    energy = rows(os.path.join(out, "energy.csv"))[1:]  # row 0: the initial state
    by_step = {int(r["step"]): r for r in energy}
    steps = sorted(by_step)
    division_steps = sorted({int(r["step"]) for r in rows(os.path.join(out, "divisions.csv"))})
    print("| step | t | cells after | dt before | first dt after | ratio | steps to dt >= dt before / 2 | failed attempts until then |")
    print("|---|---|---|---|---|---|---|---|")
    worst_steps, worst_failed, met, counted = 0, 0, 0, 0
    for i, s in enumerate(division_steps):
        if s not in by_step:
            continue
        dt_before = float(by_step[s]["dt"])
        end = division_steps[i + 1] if i + 1 < len(division_steps) else steps[-1] + 1
        after = [k for k in steps if s < k <= end]
        if not after:
            continue
        recovered, failed = None, 0
        for j, k in enumerate(after, 1):
            failed += int(by_step[k]["failed_attempts"])
            if float(by_step[k]["dt"]) >= 0.5 * dt_before:
                recovered = j
                break
        first = float(by_step[after[0]]["dt"])
        counted += 1
        if recovered is not None and recovered <= goal:
            met += 1
        worst_steps = max(worst_steps, recovered if recovered is not None else len(after))
        worst_failed = max(worst_failed, failed)
        shown = str(recovered) if recovered is not None else "not within %d (next division)" % len(after)
        if recovered is not None and recovered > goal:
            shown += " (> %d)" % goal
        print("| %d | %.6g | %s | %.3g | %.3g | %.3g | %s | %d |" % (
            s, float(by_step[s]["t"]), by_step[after[0]]["n_cells"], dt_before, first,
            first / dt_before, shown, failed))
    print()
    print("%d division steps: %d back to half their dt within %d steps; at most %d steps, "
          "at most %d failed attempts after one" % (counted, met, goal, worst_steps, worst_failed))


if __name__ == "__main__":
    main()
