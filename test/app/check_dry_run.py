"""Checks a short run of input/granular-column.yaml (sand column 0.1 m x 0.1 m, 2 x 2 particles per
2.5 mm cell, in a 0.4 m x 0.15 m box).

usage: check_dry_run.py <output directory>
"""
import csv
import glob
import os
import sys

import h5py
import numpy as np

out = sys.argv[1]
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


rows = list(csv.DictReader(open(glob.glob(os.path.join(out, "*.csv"))[0])))
expected = (0.1 / 0.00125) ** 2  # particles: (0.1 m / half a cell)^2
counts = {int(r["particles"]) for r in rows}
check(counts == {int(expected)}, "particle count %s stays %d in every row" % (sorted(counts), expected))
masses = [float(r["mass_sand"]) for r in rows]
# Particles carry their mass: it is summed in another order on other steps and ranks only.
check(max(masses) - min(masses) <= 1e-12 * masses[0], "sand mass %.12g kg/m constant" % masses[0])
check(abs(masses[0] - 1985.0 * 0.01) <= 1e-9 * masses[0], "sand mass = density x column area")
check(float(rows[-1]["time"]) == 0.05, "run reached t = 0.05 s")
check(all(r["dt_limiter"].startswith(("wave_speed(sand)", "dt_initial")) for r in rows[1:]),
      "time step limited by the sand's wave speed")

steps = sorted(glob.glob(os.path.join(out, "*_[0-9]*.h5")))
check(len(steps) == 3, "three output steps (0, 0.025, 0.05 s)")
centre = []
for path in steps:
    with h5py.File(path, "r") as f:
        p = f["particles/position"][...]
        check(p.shape == (int(expected), 2), "%s: %d particle positions" % (os.path.basename(path), p.shape[0]))
        inside = np.all((p[:, 0] >= 0) & (p[:, 0] <= 0.4) & (p[:, 1] >= 0) & (p[:, 1] <= 0.15))
        check(inside, "%s: every particle inside the box" % os.path.basename(path))
        check(f["particles/stress"].shape == (int(expected), 9), "stress has 9 components")
        volume = f["particles/volume"][...]
        check(volume.shape == (int(expected),) and bool(np.all(np.isfinite(volume) & (volume > 0))),
              "%s: every particle volume written, finite and positive" % os.path.basename(path))
        if path == steps[0]:
            # At rest the particles tile the column: their volumes sum to its area (round-off).
            check(abs(volume.sum() - 0.01) <= 1e-12, "step 0: particle volumes sum to the column's area")
        ids = f["particles/id"][...]
        check(np.unique(ids).size == int(expected), "%s: every particle id written once" % os.path.basename(path))
        if path == steps[0]:
            first_ids = np.sort(ids)
        check(np.array_equal(np.sort(ids), first_ids), "%s: the same particle ids as step 0" % os.path.basename(path))
        centre.append(p[:, 1].mean())
# The column collapses: its centre of mass falls, from 0.05 m, and cannot rise (dissipative flow).
check(abs(centre[0] - 0.05) < 1e-12, "initial centre of mass at 0.05 m (%.6f)" % centre[0])
check(centre[1] < centre[0] and centre[2] < centre[1], "centre of mass falls: %s" % np.round(centre, 5))
print("%d failure(s)" % len(failures))
sys.exit(1 if failures else 0)
