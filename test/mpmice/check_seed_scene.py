"""Checks a short run of a scene of sand in water (the seed scene, the Rzadkiewicz slide, or the sand
column collapse): every material's mass conserved (fluids to round-off, particles exactly), the
sand's centre of mass lower than at the start, every value finite, and, at every output, the kinetic
energy of all materials no more than the potential energy that the sand's descent released (its
buoyant weight times its drop: the energy budget allows nothing else).

With --no-retries, also that no step was undone and retried (the CSV's retries column).

usage: check_seed_scene.py OUTPUT_DIRECTORY [SAND_MATERIAL_INDEX (default 1: bed, sand, water, air)
                           [SURROUNDING_DENSITY (default 999.8: water; the sand's weight counts less
                           the displaced fluid's)]] [--no-retries]"""
import csv
import glob
import math
import sys

import h5py
import numpy as np

no_retries = "--no-retries" in sys.argv
args = [a for a in sys.argv[1:] if a != "--no-retries"]
out = args[0]
rows = list(csv.DictReader(open(glob.glob(out + "/*.csv")[0])))
failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


first, last = rows[0], rows[-1]
for fluid in ("water", "air"):
    m0, m1 = float(first["mass_" + fluid]), float(last["mass_" + fluid])
    # Advection conserves mass to round-off; 1e-12 relative allows the sums' rounding over the steps.
    check(abs(m1 - m0) <= 1e-12 * m0, "%s mass %.15g -> %.15g" % (fluid, m0, m1))
solids = [k[len("mass_"):] for k in first if k.startswith("mass_") and k not in ("mass_water", "mass_air")]
for solid in solids:
    check(first["mass_" + solid] == last["mass_" + solid], "%s particle mass unchanged (%s)" % (solid, last["mass_" + solid]))
finite = all(math.isfinite(float(v)) for r in rows for k, v in r.items() if k != "dt_limiter")
check(finite, "every CSV value finite")
if no_retries:
    retried = [r["step"] for r in rows if int(r["retries"]) > 0]
    check(not retried, "no step undone and retried (%d were: %s)" % (len(retried), " ".join(retried[:10])))

steps = sorted(glob.glob(out + "/*_[0-9]*.h5"))
SAND = int(args[1]) if len(args) > 1 else 1  # scene material index of the sand


def sand_centre(path):
    with h5py.File(path, "r") as f:
        x = f["particles/position"][:]
        m = f["particles/material"][:]
        return x[m == SAND].mean(axis=0)


c0, c1 = sand_centre(steps[0]), sand_centre(steps[-1])
drop = c0[1] - c1[1]
check(drop > 0, "sand centre of mass moved down by %.4f m (from %s to %s)" % (drop, c0, c1))
with h5py.File(steps[-1], "r") as f:
    check(all(np.isfinite(f[k][:]).all() for k in ("cells/pressure", "particles/position", "particles/velocity")),
          "pressure and particles finite at the end")

rho_s, g = 1985.0, 9.81
rho_w = float(args[2]) if len(args) > 2 else 999.8  # the fluid the sand moves in
sand_mass = float(last["mass_sand"])
# At every output, not only the last: a growth that later settles (into the walls' friction or the
# sand's plasticity) is still energy from nothing.
by_step = {int(r["step"]): r for r in rows}
worst = None
for path in steps[1:]:
    with h5py.File(path, "r") as f:
        step = int(f.attrs["step"])
    row = by_step[step]
    released = (1 - rho_w / rho_s) * sand_mass * g * max(c0[1] - sand_centre(path)[1], 0.0)
    kinetic = sum(float(row[k]) for k in ("kinetic_energy_water", "kinetic_energy_air", "kinetic_energy_particles"))
    if worst is None or kinetic - released > worst[0] - worst[1]:
        worst = (kinetic, released, float(row["time"]))
check(worst[0] <= worst[1], "kinetic energy within what the descent released at every output (tightest: %.4g against "
      "%.4g J/m at %.3g s)" % worst)
sys.exit(1 if failures else 0)
