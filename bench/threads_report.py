#!/usr/bin/python3
"""Table of bench/threads.sh's runs: wall time per phase, speed-up and efficiency of 2 threads and 2 ranks.

usage: bench/threads_report.py <directory with bench_{ice,mpm}.{ranks,threads}{1,2}.run<k>.txt>

Times are wall-clock per cell-step (ICE) or per particle-step (MPM) of the whole job, so that
1 rank x 2 threads and 2 ranks x 1 thread compare directly; speed-up = time(1) / time(2) and
efficiency = speed-up / 2. Of repeated runs of a configuration the one with the fastest whole step
is reported (load from other jobs only ever slows a run down).
"""
import glob
import os
import re
import sys


def ice_phases(text):
    """{phase: wall us per cell-step} from bench_ice's table (first numeric column)."""
    phases, table = {}, False
    for line in text.splitlines():
        if line.startswith("phase"):
            table = True
            continue
        if table:
            match = re.match(r"^(\S.*?)\s{2,}([0-9.eE+-]+)", line)
            if not match:
                break
            phases[match.group(1).strip()] = float(match.group(2))
    return phases


def mpm_phases(text):
    """{phase: wall us per particle-step}: the whole step, and each phase's share of it."""
    ranks = int(re.search(r"(\d+) rank\(s\)", text).group(1))
    whole = float(re.search(r"whole step: ([0-9.eE+-]+) core-us per particle-step", text).group(1)) / ranks
    phases = {"step": whole}
    for name, share in re.findall(r"^\s+(\S+)\s+([0-9.]+) % \(rank 0\)", text, re.M):
        phases[name] = whole * float(share) / 100.0
    return phases


def main():
    directory = sys.argv[1]
    for bench, parse, unit in (("bench_ice", ice_phases, "us per cell-step"),
                               ("bench_mpm", mpm_phases, "us per particle-step")):
        runs, counts = {}, {}
        for key in ("ranks1", "ranks2", "threads1", "threads2"):
            files = sorted(glob.glob(os.path.join(directory, "%s.%s.run*.txt" % (bench, key))))
            candidates = [parse(open(f).read()) for f in files]
            runs[key] = min(candidates, key=lambda phases: phases["step"])
            counts[key] = len(candidates)
        print("\n%s: wall %s (Serial build: ranks; OpenMP build: threads of one rank); fastest of %s runs"
              % (bench, unit, "/".join(str(counts[k]) for k in counts)))
        print("%-24s %9s %9s %9s %9s   %-18s %-18s" % ("phase", "1 rank", "2 ranks", "1 thread", "2 threads",
                                                     "ranks: x, eff.", "threads: x, eff."))
        for phase in runs["ranks1"]:
            values = [runs[k].get(phase, float("nan")) for k in ("ranks1", "ranks2", "threads1", "threads2")]
            ranks = values[0] / values[1] if values[1] > 0 else float("nan")
            threads = values[2] / values[3] if values[3] > 0 else float("nan")
            print("%-24s %9.4f %9.4f %9.4f %9.4f   %5.2fx  %4.0f %%      %5.2fx  %4.0f %%"
                  % (phase, *values, ranks, 50 * ranks, threads, 50 * threads))
        step = [runs[k]["step"] for k in ("ranks1", "ranks2", "threads1", "threads2")]
        print("whole step: 2 threads are %.2fx as fast as 1 thread and %.2fx as fast as 2 ranks;"
              " 1 thread (OpenMP build) vs 1 rank (Serial build): %.2fx"
              % (step[2] / step[3], step[1] / step[3], step[0] / step[2]))


if __name__ == "__main__":
    main()
