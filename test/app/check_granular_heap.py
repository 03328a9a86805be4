"""The heap left by input/granular-column.yaml (column 0.1 m x 0.1 m, friction angle 30 deg).

usage: check_granular_heap.py <output directory>

- At rest: the fastest particle moves at less than 5 % of the peak speed sqrt(g H) ~ 1 m/s.
- Runout: for columns of aspect ratio a < ~2, experiments give (L - L0) / L0 = 1.2 a (Lube et al.
  2005, J. Fluid Mech. 541; Lajeunesse et al. 2005, Phys. Fluids 17) with a scatter of about
  +-20 % between materials and set-ups: that scatter is the tolerance.
- Slope of the deposit's flank (least-squares line through the surface heights between 20 % and 80 %
  of the runout): a cohesionless heap at rest cannot stand steeper than its friction angle, and a
  collapse leaves it a few degrees below; it must lie between half the friction angle and the angle.
"""
import glob
import math
import os
import sys

import h5py
import numpy as np

out = sys.argv[1]
L0, H0, phi = 0.1, 0.1, 30.0
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


last = sorted(glob.glob(os.path.join(out, "*_[0-9]*.h5")))[-1]
with h5py.File(last, "r") as f:
    p = f["particles/position"][...]
    v = f["particles/velocity"][...]
speed = np.sqrt((v ** 2).sum(axis=1)).max()
check(speed < 0.05 * math.sqrt(9.81 * H0), "at rest: fastest particle %.4f m/s" % speed)
runout = p[:, 0].max()
scaled = (runout - L0) / L0
check(abs(scaled / 1.2 - 1) <= 0.2, "runout (L - L0)/L0 = %.3f vs 1.2 a = 1.2 (+-20 %%)" % scaled)
width = 0.005
xs = np.arange(0.2 * runout, 0.8 * runout, width)
heights = np.array([p[(p[:, 0] >= x) & (p[:, 0] < x + width), 1].max() for x in xs])
slope = -np.polyfit(xs + 0.5 * width, heights, 1)[0]
angle = math.degrees(math.atan(slope))
check(0.5 * phi <= angle <= phi, "flank slope %.1f deg, friction angle %.0f deg" % (angle, phi))
print("%d failure(s)" % len(failures))
sys.exit(1 if failures else 0)
