#!/usr/bin/python3
"""Compare two cfdmpm output directories field by field, step by step.

usage: utilities/compare_runs.py <directory A> <directory B> [--tolerance 1e-10] [--last]

Both runs must write the same output steps (same scene, same time-step sequence), e.g. the same
scene on 1 and 2 MPI ranks, or on the Serial and the OpenMP build. For every HDF5 step present in
both, every cell dataset (per material and the pressure) and every particle dataset is compared:

    difference = max |a - b| / scale,   scale = max |a| over the field (1 if the field is all zero)

i.e. the largest deviation relative to the field's own magnitude, the measure the project's
1-vs-2-rank tests use. Particles are matched by their `id` dataset when the files have one, else
by their position in the file (the same when both runs use the same number of ranks). Prints the
worst difference per field and exits with status 1 if any exceeds --tolerance, 2 if the runs do not
have the same steps or fields.
"""
import argparse
import glob
import os
import re
import sys

import h5py
import numpy as np


def steps(directory):
    found = {}
    for path in glob.glob(os.path.join(directory, "*_[0-9]*.h5")):
        match = re.search(r"_(\d+)\.h5$", path)
        if match:
            found[int(match.group(1))] = path
    return found


def datasets(group, prefix=""):
    names = []
    for key, item in group.items():
        name = prefix + key
        if isinstance(item, h5py.Group):
            names += datasets(item, name + "/")
        else:
            names.append(name)
    return names


def fields(f):
    """Dataset paths to compare: cells and particles (padded copies and node data excluded)."""
    names = []
    for top in ("cells", "particles"):
        if top in f:
            names += [top + "/" + n for n in datasets(f[top])]
    return sorted(names)


def particle_order(f):
    if "particles/id" in f:
        return np.argsort(f["particles/id"][...], kind="stable")
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("a")
    parser.add_argument("b")
    parser.add_argument("--tolerance", type=float, default=1e-10,
                        help="largest accepted max|a-b|/max|a| per field (default 1e-10)")
    parser.add_argument("--last", action="store_true", help="compare the last common step only")
    args = parser.parse_args()

    steps_a, steps_b = steps(args.a), steps(args.b)
    if not steps_a or not steps_b:
        sys.exit("compare_runs.py: no output steps in " + (args.a if not steps_a else args.b))
    if sorted(steps_a) != sorted(steps_b):
        print("compare_runs.py: the runs wrote different steps: %s vs %s" % (sorted(steps_a), sorted(steps_b)))
        sys.exit(2)
    common = sorted(steps_a)
    if args.last:
        common = common[-1:]

    worst = {}
    for step in common:
        with h5py.File(steps_a[step], "r") as fa, h5py.File(steps_b[step], "r") as fb:
            ta, tb = float(fa.attrs["time"]), float(fb.attrs["time"])
            if ta != tb and abs(ta - tb) > 1e-12 * max(abs(ta), 1.0):
                print("compare_runs.py: step %d is at t = %.17g in A and %.17g in B" % (step, ta, tb))
                sys.exit(2)
            names_a, names_b = fields(fa), fields(fb)
            if names_a != names_b:
                print("compare_runs.py: step %d has different fields: %s vs %s" % (step, names_a, names_b))
                sys.exit(2)
            order_a, order_b = particle_order(fa), particle_order(fb)
            for name in names_a:
                a, b = fa[name][...], fb[name][...]
                if a.shape != b.shape:
                    print("compare_runs.py: step %d, %s: shapes %s vs %s" % (step, name, a.shape, b.shape))
                    sys.exit(2)
                if name.startswith("particles/") and order_a is not None and order_b is not None:
                    a, b = a[order_a], b[order_b]
                a, b = a.astype(np.float64), b.astype(np.float64)
                scale = np.max(np.abs(a)) if a.size else 0.0
                diff = np.max(np.abs(a - b)) / (scale if scale > 0 else 1.0) if a.size else 0.0
                if name not in worst or diff > worst[name][0]:
                    worst[name] = (diff, step)

    failed = False
    width = max(len(n) for n in worst)
    print("%d common steps; largest max|a-b|/max|a| per field (tolerance %.1e):" % (len(common), args.tolerance))
    for name in sorted(worst):
        diff, step = worst[name]
        flag = "  EXCEEDS" if diff > args.tolerance else ""
        failed = failed or diff > args.tolerance
        print("  %-*s %10.3e  (step %d)%s" % (width, name, diff, step, flag))
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
