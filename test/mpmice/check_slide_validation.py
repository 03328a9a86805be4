"""The wave of a 20 mm run of the submarine slide at t = 0.4 s against cfdmpm's 5 mm run of the same
scene (data/reference/cfdmpm-rzadkiewicz-5mm.csv, made by utilities/slide_chart.py reference): the
trough's depth and position, measured as utilities/slide_profile.py measures them.

The bounds are the 20 mm run's discretisation error, estimated from the resolutions run before the
test was written (doc/validation.md): for a method of first order the error of a run is, by
Richardson, about twice its difference from the run with cells of half the size, and the 20 mm and
10 mm troughs at 0.4 s differ by 7.2 mm in depth and 5 mm in position. A 5 mm reference lies inside
that estimate if the runs converge at first order or better.
  depth:    2 x 7.2 mm, rounded up to 15 mm (of a trough ~90 mm deep);
  position: the trough sits at a column centre (20 mm apart): one column plus 2 x 5 mm, 30 mm.

usage: check_slide_validation.py OUTPUT_DIRECTORY REFERENCE_CSV"""
import argparse
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "utilities"))
import openfoam_slide  # noqa: E402  (read_eta_csv)
import slide_profile  # noqa: E402

TIME = 0.4
DEPTH_BOUND = 0.015     # m, see above
POSITION_BOUND = 0.030  # m, see above

out, reference_csv = sys.argv[1], sys.argv[2]
args = argparse.Namespace(still_level=1.6, sand_index=1, densities=(1985.0, 999.8))
runs = {round(r["time"], 6): r for r in slide_profile.profile(out, args)}
reference = openfoam_slide.read_eta_csv(reference_csv)
if TIME not in runs or TIME not in reference:
    sys.exit("FAIL  no eta at t = %g s in the run (%s) or in the reference (%s)" % (TIME, sorted(runs), sorted(reference)))
run = runs[TIME]
x, eta = np.array(reference[TIME]).T
lo = int(np.nanargmin(eta))
failures = 0
for what, value, expected, bound in (("depth", run["trough"], eta[lo], DEPTH_BOUND),
                                     ("position", run["trough_x"], x[lo], POSITION_BOUND)):
    ok = abs(value - expected) <= bound
    failures += not ok
    print("%s  trough %s at %g s: %.4f m, reference %.4f m (difference %.4f m, bound %.3f m)" % (
        "ok  " if ok else "FAIL", what, TIME, value, expected, value - expected, bound))
print("      eta RMS against the reference: %.4f m" % slide_profile.eta_rms(run["x"], run["eta"], x, eta))
sys.exit(1 if failures else 0)
