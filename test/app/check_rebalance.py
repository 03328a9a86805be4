#!/usr/bin/python3
"""The CSV of a run with domain.rebalance_interval set (B) against one without (A).

usage: check_rebalance.py <A.csv> <B.csv> <ranks> <interval>

B has the columns imbalance_before, imbalance_after, patches_moved, filled on the rows of the steps
that follow a rebalance (steps 1, interval + 1, ...) and empty on the others; A has none of them.
Imbalances are >= 0 and after <= before; a row with patches moved has after < before - 0.02 (the
driver's kRebalanceGain). On one rank nothing moves and the imbalance is 0; on more, the first
rebalance (before step 1: the particles are gathered in a corner from the start) moves patches.
"""
import csv
import sys


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main():
    a, b = rows(sys.argv[1]), rows(sys.argv[2])
    ranks, interval = int(sys.argv[3]), int(sys.argv[4])
    columns = ("imbalance_before", "imbalance_after", "patches_moved")
    problems = []
    if any(c in a[0] for c in columns):
        problems.append("the run without rebalancing has rebalance columns")
    if not all(c in b[0] for c in columns):
        sys.exit("check_rebalance.py: %s lacks the columns %s" % (sys.argv[2], ", ".join(columns)))
    moved_rows = 0
    for row in b[1:]:
        step = int(row["step"])
        due = (step - 1) % interval == 0
        values = [row[c] for c in columns]
        if not due:
            if any(values):
                problems.append("step %d: rebalance columns filled (%s) on a step without a rebalance" % (step, values))
            continue
        if not all(values):
            problems.append("step %d: rebalance columns empty after a rebalance step" % step)
            continue
        before, after, moved = float(values[0]), float(values[1]), int(values[2])
        if before < 0 or after < 0 or after > before:
            problems.append("step %d: imbalance before %g, after %g" % (step, before, after))
        if moved > 0:
            moved_rows += 1
            if not after < before - 0.02:
                problems.append("step %d: %d patches moved for imbalance %g -> %g" % (step, moved, before, after))
        elif after != before:
            problems.append("step %d: nothing moved but the imbalance changed %g -> %g" % (step, before, after))
        if ranks == 1 and (moved or before != 0):
            problems.append("step %d: one rank, yet imbalance %g, %d patches moved" % (step, before, moved))
        if step == 1:
            print("first rebalance: imbalance %.4f -> %.4f, %d patches moved" % (before, after, moved))
    print("%d rebalances moved patches in %d steps" % (moved_rows, len(b) - 1))
    if ranks > 1:
        first = next(row for row in b if row["step"] == "1")
        if int(first["patches_moved"]) == 0:
            problems.append("the first rebalance moved nothing, though the sand is gathered in a corner")
    if len(a) != len(b):
        problems.append("the runs have %d and %d rows" % (len(a), len(b)))
    for p in problems:
        print("check_rebalance.py:", p)
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
