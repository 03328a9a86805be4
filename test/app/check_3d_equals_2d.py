#!/usr/bin/python3
"""The 3-D code path against the 2-D one on a scene that does not depend on z.

usage: check_3d_equals_2d.py write <scene.yaml> <work dir>   -> writes 2d.yaml and 3d.yaml
       check_3d_equals_2d.py check <work dir>                 -> compares their outputs

The dam break (coarsened to 10 mm cells, 0.05 s) is run once in 2-D and once in 3-D, five cells deep
with free-slip walls in z. In 3-D nothing then varies along z (w = 0 exactly), so every z-slice of
the 3-D run must equal the 2-D run: the same steps at the same times, and fields that differ only
by the linear solver's round-off. Both runs solve the pressure to a relative residual of 1e-12
(tighter stalls in Belos CG). The 2-D and 3-D matrices get different MueLu hierarchies, so the
pressure corrections differ at the solver's tolerance in every outer iteration and the velocities
integrate that over the run's ~40 steps (measured: 4e-11 of scale); the bound is the one of the
1-vs-2-rank dam-break test, 1e-10 of each field's scale. A wrong z-wall, a 3-D stencil or flux error
gives differences of order 1.
"""
import glob
import os
import sys

import h5py
import numpy as np
import yaml


def write(scene, work):
    with open(scene) as f:
        base = yaml.safe_load(f)
    s = base["cfdmpm"]
    s["domain"]["cells"] = [50, 20]
    s["domain"]["patch_cells"] = [10, 10]
    s["time"]["end_time"] = 0.05
    s["output"]["interval"] = 0.025
    s["output"]["fields"] = ["volume_fraction", "density", "velocity", "pressure"]
    s["ice"] = dict(s.get("ice") or {}, solver_tolerance=1e-12)
    for dim in (2, 3):
        t = yaml.safe_load(yaml.safe_dump(base))
        d = t["cfdmpm"]
        d["output"]["directory"] = os.path.join(work, "%dd" % dim)
        if dim == 3:
            dom = d["domain"]
            dom["dimension"] = 3
            dom["lower"] = dom["lower"] + [0.0]
            dom["upper"] = dom["upper"] + [0.05]
            dom["cells"] = dom["cells"] + [5]
            dom["patch_cells"] = dom["patch_cells"] + [5]
            dom["gravity"] = dom["gravity"] + [0.0]
            for region in d["regions"].values():
                region["lower"] = region["lower"] + [0.0]
                region["upper"] = region["upper"] + [0.05]
            d["boundary_conditions"]["z-"] = {"velocity": "free_slip", "temperature": "zero_gradient"}
            d["boundary_conditions"]["z+"] = {"velocity": "free_slip", "temperature": "zero_gradient"}
        with open(os.path.join(work, "%dd.yaml" % dim), "w") as f:
            # Lists in flow style ([a, b]): the Teuchos YAML reader rejects a block list at its key's indentation
            # and a flow collection broken over lines.
            yaml.safe_dump(t, f, default_flow_style=None, width=100000)


def check(work):
    failures = []
    steps2 = sorted(glob.glob(os.path.join(work, "2d", "*_[0-9]*.h5")))
    steps3 = sorted(glob.glob(os.path.join(work, "3d", "*_[0-9]*.h5")))
    names = lambda paths: [os.path.basename(p).split("_")[-1] for p in paths]
    if len(steps2) < 3 or names(steps2) != names(steps3):
        failures.append("different output steps: %s vs %s" % (names(steps2), names(steps3)))
    worst = {}
    for p2, p3 in zip(steps2, steps3):
        with h5py.File(p2, "r") as f2, h5py.File(p3, "r") as f3:
            if f2.attrs["time"] != f3.attrs["time"]:
                failures.append("%s: t = %r (2-D) vs %r (3-D)" % (names([p2])[0], f2.attrs["time"], f3.attrs["time"]))
            for key in ["pressure"] + ["%s/%s" % (m, q) for m in ("water", "air")
                                       for q in ("volume_fraction", "density", "velocity")]:
                a, b = f2["cells/" + key][...], f3["cells/" + key][...]
                scale = max(np.max(np.abs(a)), 1e-300)
                if key.endswith("velocity"):
                    # w is driven only by the pressure solve's z-asymmetric round-off (MueLu's
                    # aggregates are not symmetric in z), so it is bounded like the differences.
                    w = np.max(np.abs(b[..., 2])) / scale
                    worst[key + " (w)"] = max(worst.get(key + " (w)", 0.0), w)
                    b = b[..., :2]
                diff = np.max(np.abs(b - a[None, ...])) / scale
                worst[key] = max(worst.get(key, 0.0), diff)
    for key, value in sorted(worst.items()):
        bound = 1e-10
        ok = value <= bound
        print("  %-28s %.3e of scale (bound %.0e)%s" % (key, value, bound, "" if ok else "  FAILED"))
        if not ok:
            failures.append(key)
    print("%d failure(s)%s" % (len(failures), (": " + "; ".join(failures)) if failures else ""))
    return 1 if failures else 0


if __name__ == "__main__":
    if sys.argv[1] == "write":
        write(sys.argv[2], sys.argv[3])
    else:
        sys.exit(check(sys.argv[2]))
