"""Checks a run of input/floating-block.yaml: a square block of relative density 0.5, placed 5
degrees off upright in still water, turns corner-down (hydrostatics: 45 degrees) and floats with
its centre at the water level.

usage: check_floating_block.py OUTPUT_DIRECTORY INITIAL_ANGLE_DEGREES WATER_LEVEL CELL_SIZE"""
import csv
import glob
import math
import re
import sys

import h5py
import numpy as np

out, initial, level, h = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def load(path):
    with h5py.File(path, "r") as f:
        ids = f["particles/id"][:]
        x = f["particles/position"][:, :2]
    order = np.argsort(ids)
    return ids[order], x[order]


files = sorted(glob.glob(out + "/*_[0-9]*.h5"), key=lambda p: int(re.findall(r"_(\d+)\.h5$", p)[0]))
check(len(files) >= 3, f"{len(files)} outputs")
ids0, x0 = load(files[0])
a = x0 - x0.mean(axis=0)
angles, heights = [], []
for path in files:
    ids, x = load(path)
    if not np.array_equal(ids, ids0):
        check(False, f"{path}: the same particles as at the start")
        continue
    centre = x.mean(axis=0)
    b = x - centre
    # The rotation that best maps the initial particles onto these (2-D Kabsch): the body's turn.
    turn = math.degrees(math.atan2(np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]), np.sum(a * b)))
    angles.append(initial + turn)
    heights.append(centre[1])
check(np.all(np.isfinite(angles)) and np.all(np.isfinite(heights)), "particle positions finite")
print("      angle (degrees) at each output: " + " ".join(f"{t:.1f}" for t in angles))
# Upright is unstable: the block turns one way, away from 0, and does not come back.
check(abs(angles[-1]) > abs(angles[0]), f"turned away from upright: {angles[0]:.1f} -> {angles[-1]:.1f} degrees")
# The corner-down equilibrium is at 45 degrees. The last few degrees come slowly (the turning
# moment vanishes there, and the water in the block's cells moves with it through the exchange);
# 5 degrees allows that approach (42 degrees at 2.4 s when written) and no more: the block held by
# its own coverage pressure stopped at 17-18 degrees.
check(abs(abs(angles[-1]) - 45.0) <= 5.0, f"corner-down at the end: {abs(angles[-1]):.1f} degrees (45 +- 5)")
# Half submerged at any orientation that is symmetric about the vertical through the centre, i.e.
# upright and corner-down; in between by at most a few per cent of the side. A fifth of a cell.
worst = max(abs(y - level) for y in heights)
check(worst <= 0.2 * h, f"centre at the water level at every output: largest departure {worst * 1000:.2f} mm (bound {0.2 * h * 1000:.1f} mm)")

rows = list(csv.DictReader(open(glob.glob(out + "/*.csv")[0])))
for fluid in ("water", "air"):
    m0, m1 = float(rows[0]["mass_" + fluid]), float(rows[-1]["mass_" + fluid])
    # Advection conserves mass to round-off; 1e-12 relative allows the sums' rounding over the steps.
    check(abs(m1 - m0) <= 1e-12 * m0, "%s mass %.15g -> %.15g" % (fluid, m0, m1))
# Each particle keeps its mass; their sum in the CSV is taken in the order the ranks hold them,
# which changes as the block's particles move between ranks: round-off of 256 terms.
w0, w1 = float(rows[0]["mass_wood"]), float(rows[-1]["mass_wood"])
check(abs(w1 - w0) <= 1e-13 * w0, "wood particle mass %.17g -> %.17g" % (w0, w1))
check(all(r["retries"] == "0" for r in rows), "no step retried")
if failures:
    sys.exit(1)
