#!/usr/bin/python3
"""Table of bench/compare.sh's runs: per phase, the median of the paired ratios (this / reference)
and the fastest wall time of each build, in us per cell-step; and the CG iterations per step.

usage: bench/compare_report.py <directory with {reference,current}.run<k>.txt>
"""
import glob
import os
import re
import statistics
import sys

from threads_report import ice_phases


def iterations(text):
    match = re.search(r"pressure iterations per step: ([0-9.]+)", text)
    return float(match.group(1)) if match else float("nan")


def main():
    directory = sys.argv[1]
    rounds = len(glob.glob(os.path.join(directory, "reference.run*.txt")))
    pairs = []
    for r in range(1, rounds + 1):
        texts = [open(os.path.join(directory, "%s.run%d.txt" % (b, r))).read() for b in ("reference", "current")]
        pairs.append([(ice_phases(t), iterations(t)) for t in texts])
    print("\nICE benchmark, %d alternating rounds; wall us per cell-step" % rounds)
    print("%-34s %10s %10s %14s" % ("phase", "reference", "this", "this / ref."))
    for phase in pairs[0][0][0]:
        ratios = [p[1][0][phase] / p[0][0][phase] for p in pairs if p[0][0].get(phase, 0) > 0 and phase in p[1][0]]
        fastest = [min(p[b][0].get(phase, float("nan")) for p in pairs) for b in (0, 1)]
        median = statistics.median(ratios) if ratios else float("nan")
        spread = "(%.2f-%.2f)" % (min(ratios), max(ratios)) if ratios else ""
        print("%-34s %10.4f %10.4f %6.3f %s" % (phase, fastest[0], fastest[1], median, spread))
    print("CG iterations per step: reference %.2f, this %.2f" % (pairs[0][0][1], pairs[0][1][1]))


if __name__ == "__main__":
    main()
