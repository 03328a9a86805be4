"""Checks the initial state that `cfdmpm` wrote for the dam-break scene (Martin & Moyce column).

usage: check_initial_state.py <output directory> <scene.yaml>
"""
import csv
import glob
import os
import sys

import h5py
import numpy as np

out, scene = sys.argv[1], sys.argv[2]
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


# Scene constants (input/dam-break.yaml): tank 0.5 x 0.2 m, column a x 2a, g = 9.81.
a, h, height, g, p_top = 0.05715, 0.1143, 0.2, 9.81, 101325.0
rho_water = 998.0
rho_air = p_top / (287.0 * 293.15)

files = sorted(glob.glob(os.path.join(out, "*_000000.h5")))
check(len(files) == 1, "one HDF5 file for step 0: %s" % files)
check(not glob.glob(os.path.join(out, "*.tmp")), "no temporary files left")
series = glob.glob(os.path.join(out, "*.xmf"))
check(len(series) >= 2, "XDMF step file and time series written: %s" % series)

with h5py.File(files[0], "r") as f:
    cells = f["cells"]
    nx, ny = int(cells.attrs["count_xyz"][0]), int(cells.attrs["count_xyz"][1])
    dx, dy = float(cells.attrs["spacing_xyz"][0]), float(cells.attrs["spacing_xyz"][1])
    theta_w = cells["water/volume_fraction"][...]
    theta_a = cells["air/volume_fraction"][...]
    p = cells["pressure"][...]
    rho_w = cells["water/density"][...]
    vel = cells["water/velocity"][...]
    check(theta_w.shape == (ny, nx), "datasets are (ny, nx) = (%d, %d)" % (ny, nx))
    check(vel.shape == (ny, nx, 2), "velocity has two components per cell")

# Volume fractions sum to one (exact: sampled fractions are multiples of 1/16).
check(np.max(np.abs(theta_w + theta_a - 1.0)) < 1e-15, "water + air volume fractions = 1")
# Water area: each sampled interface misplaces at most half a sample spacing (1/8 cell) along its
# length, so |error| <= (dx/8) h + (dy/8) a.
area = theta_w.sum() * dx * dy
bound = dx / 8 * h + dy / 8 * a
check(abs(area - a * h) <= bound, "water area %.6e vs %.6e (bound %.1e)" % (area, a * h, bound))

# Hydrostatic pressure. In the water column below the interface the pressure difference between two
# cells is rho g dy per cell to the water's compressibility (dp / c^2 ~ 1e-6 relative): 1e-5.
j_low, j_high = 2, int(0.8 * h / dy)
dp = p[j_low, 0] - p[j_high, 0]
expected = rho_water * g * (j_high - j_low) * dy
check(abs(dp / expected - 1) < 1e-5, "pressure difference in water %.4f Pa vs rho g dh = %.4f Pa" % (dp, expected))
# At the floor under the column: p_top + air weight + water weight; the interface cell is resolved
# to within a cell, so the bound is rho_water g dy.
y0 = 0.5 * dy
p_floor = p_top + rho_air * g * (height - h) + rho_water * g * (h - y0)
check(abs(p[0, 0] - p_floor) < rho_water * g * dy, "floor pressure %.2f Pa vs %.2f Pa" % (p[0, 0], p_floor))
# Water density from its equation of state at ~1 atm: 998 kg/m^3 to (dp / c^2) ~ 1e-6.
rho_micro = rho_w[0, 0] / theta_w[0, 0]
check(abs(rho_micro / rho_water - 1) < 1e-5, "water density %.4f kg/m^3" % rho_micro)
check(np.all(vel == 0.0), "fluid at rest")

# The diagnostics CSV: step 0 with the mass of each material (per metre of depth in 2-D).
csv_files = glob.glob(os.path.join(out, "*.csv"))
check(len(csv_files) == 1, "one CSV time series")
with open(csv_files[0]) as f:
    rows = list(csv.DictReader(f))
check(len(rows) >= 1 and rows[0]["step"] == "0", "CSV row for step 0")
mass_w = float(rows[0]["mass_water"])
check(abs(mass_w - rho_water * area) <= 1e-5 * rho_water * area,
      "water mass %.6f kg/m = density x sampled area" % mass_w)

print("%d failure(s)" % len(failures))
sys.exit(1 if failures else 0)
