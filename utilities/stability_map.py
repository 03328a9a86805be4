#!/usr/bin/env python3
"""The stability map (issue 14, doc/stability.md): one PNG with a panel per stability case.

Reads the sweeps that the stability tests write (stability_<case>_np<ranks>.csv: columns parameter,
value, method, status; comment lines "# threshold <label> = <value>") and draws, per case, the
swept parameter on x, the error or growth factor on y, the weak method and cfdmpm's on the same
axes, failed runs as crosses and the failure thresholds as vertical lines.

usage: utilities/stability_map.py [--dir DIR]... [--ranks N] [--out PNG]

DIR (repeatable) defaults to build/test/stability and build/test/mpm (where ctest runs the fluid
cases and the MPM cases (f)-(h); or the directory given to the tests in $CFDMPM_STABILITY_DIR); N
picks the rank count whose CSVs are drawn (default 1); PNG defaults to doc/stability-map.png.
Prints the thresholds it found.
"""
import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# (file stem or tuple of stems, panel title, x label, y label, x log, y log, horizontal reference
# lines (y, label)). A method is drawn solid when its name contains "cfdmpm", dashed otherwise.
PANELS = [
    ("stability_a_pressure", "(a) pressure: explicit vs implicit",
     "acoustic Courant number c Δt / h", "largest |u| in 400 steps / slug speed", True, True,
     [(10.0, "failure bound (10x)")]),
    ("stability_b_added_mass", "(b) added mass: a disk released in still water",
     "density ratio disk / water", "|a / potential flow's - 1| + oscillation (failed: 10)", True, True,
     [(0.1, "10 % bound")]),
    ("stability_c_drag", "(c) stiff drag, Δt = 1e-4 s",
     "exchange coefficient K (kg/(m³ s))", "relative velocity after one step / before", True, True,
     [(1.0, "|w'/w| = 1: growth above")]),
    ("stability_d_still_surface", "(d) still surface under a gas",
     "density ratio liquid / gas", "largest speed in 1 s (m/s)", True, True,
     [(1e-4, "bound 1e-4 m/s")]),
    ("stability_d_dam_break", "(d) dam break, 5 mm cells",
     "density ratio liquid / gas", "largest KE / energy released (0.01-0.25 s)", True, False,
     [(1.0, "energy released (+ U: bound)")]),
    ("stability_e_vanishing", "(e) vanishing water: slug in an air channel",
     "slug speed (m/s)", "relative mass change; smallest θ_water", False, True,
     [(1e-12, "θ = 1e-12; mass bound 1e-12")]),
    ("stability_mpm_crossing", "(f) cell crossing: column under its weight",
     "cells over the column's height", "RMS σ_yy error / (ρ g H)", True, True,
     [(0.02, "GIMP bound at 32 cells")]),
    ("stability_mpm_drift", "(f) USL vs MUSL: bar, 1000 steps, pure FLIP",
     "Courant number", "|energy change| / initial", False, True, []),
    ("stability_mpm_flip", "(f) PIC/FLIP blend: bar, 1000 steps, MUSL",
     "FLIP fraction (1 = pure FLIP, 0 = PIC)", "energy lost / initial; noise / v0", False, True, []),
    ("stability_mpm_ppc", "(f) particles per cell: bar period, 32 cells",
     "particles per cell and direction", "|period / (2L/c) - 1|; column RMS σ_yy error / (ρ g H)", False, True,
     [(0.01, "bound 1 %"), (4.0e-4, "lumped-mass dispersion (π/32)²/24")]),
    (("stability_g_rest", "stability_g_release"), "(g) block on a 20° incline, μ = 0.4",
     "cell size (mm)", "speed along the incline at rest (m/s)", False, True,
     [(0.01 * 1.09e-5 / 0.5, "bound: 1 % of the elastic shear in 0.5 s")]),
    ("stability_i_slide_cfl", "(i) seed scene, 40 mm, to 0.4 s: particle step",
     "Courant number (the particles' wave speed sets Δt)", "median equilibration jump (Pa)", False, True, []),
    ("stability_i_fluid_cfl", "(i) dam break: fluid step alone",
     "convective Courant number", "retried steps to 0.25 s (none: 0.1)", False, True,
     [(1.0, "one retry")]),
    ("stability_h_touch", "(h) two disks, MUSL, frictionless contact",
     "cells across the unit square", "energy lost / gained (fraction)", False, False,
     [(0.01, "gain bound 1 %")]),
]


def read_sweep(path):
    rows, thresholds = [], []
    with open(path) as f:
        lines = f.readlines()
    for line in lines:
        if line.startswith("# threshold "):
            label, value = line[len("# threshold "):].rsplit("=", 1)
            thresholds.append((label.strip(), float(value)))
    for r in csv.DictReader(line for line in lines if not line.startswith("#")):
        rows.append((float(r["parameter"]), float(r["value"]), r["method"], r["status"]))
    return rows, thresholds


def sweeps_for(directories, stems, ranks):
    """The CSVs of one panel: every file starting with one of its stems (drag: cell + scene), in
    any of the directories."""
    suffix = "_np%d.csv" % ranks
    stems = (stems,) if isinstance(stems, str) else stems
    found = []
    for directory in directories:
        if os.path.isdir(directory):
            found += sorted(os.path.join(directory, n) for n in os.listdir(directory)
                            if n.startswith(stems) and n.endswith(suffix))
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--dir", action="append",
                        help="directory of the CSVs (repeatable; default build/test/stability and build/test/mpm)")
    parser.add_argument("--ranks", type=int, default=1)
    parser.add_argument("--out", default=os.path.join(ROOT, "doc", "stability-map.png"))
    args = parser.parse_args()
    dirs = args.dir or [os.path.join(ROOT, "build", "test", d) for d in ("stability", "mpm")]
    if not any(os.path.isdir(d) for d in dirs):
        sys.exit("stability_map.py: none of %s exists (run `ctest -L stability` first)" % ", ".join(dirs))

    panels = [(p, sweeps_for(dirs, p[0], args.ranks)) for p in PANELS]
    panels = [(p, files) for p, files in panels if files]
    if not panels:
        sys.exit("stability_map.py: no stability_*_np%d.csv in %s" % (args.ranks, ", ".join(dirs)))
    columns = 3
    rows_n = (len(panels) + columns - 1) // columns
    fig, axes = plt.subplots(rows_n, columns, figsize=(5.2 * columns, 4.2 * rows_n), squeeze=False)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for k, ((stem, title, xlabel, ylabel, xlog, ylog, references), files) in enumerate(panels):
        ax = axes[k // columns][k % columns]
        methods, thresholds = {}, []
        for path in files:
            rows, found = read_sweep(path)
            thresholds += found
            for x, y, method, status in rows:
                methods.setdefault(method, []).append((x, y, status))
        for i, (method, points) in enumerate(methods.items()):
            points.sort()
            if ylog:  # a zero (no energy gained, no drift) has no place on a log axis
                points = [p for p in points if p[1] > 0]
                if not points:
                    continue
            colour = colours[i % len(colours)]
            weak = "cfdmpm" not in method and "mass change" not in method
            xs = [p[0] for p in points]
            ys = [p[1] for p in points]
            ax.plot(xs, ys, "-" if not weak else "--", color=colour, lw=1.2,
                    label=method + (" (weak)" if weak and "smallest" not in method else ""))
            ok = [(x, y) for (x, _, s), y in zip(points, ys) if s == "ok"]
            bad = [(x, y) for (x, _, s), y in zip(points, ys) if s != "ok"]
            if ok:
                ax.plot(*zip(*ok), "o", color=colour, ms=3.5)
            if bad:
                ax.plot(*zip(*bad), "x", color="red", ms=7, mew=1.8)
        for y, label in references:
            ax.axhline(y, color="0.5", lw=0.8, ls=":")
            ax.annotate(label, (0.98, y), xycoords=("axes fraction", "data"), fontsize=7, color="0.35",
                        va="bottom", ha="right")
        for j, (label, x) in enumerate(thresholds):
            ax.axvline(x, color=["red", "0.4", "0.6"][j % 3], lw=1.0, ls="-." if j else "-")
            ax.annotate("%s\n%.4g" % (label, x), (x, 0.97 - 0.16 * j), xycoords=("data", "axes fraction"),
                        fontsize=7, rotation=0, ha="left", va="top", color="red" if j == 0 else "0.3")
            print("%s: %s = %.6g" % (stem, label, x))
        if xlog:
            ax.set_xscale("log")
        if ylog:
            ax.set_yscale("log")
            ax.yaxis.set_major_locator(matplotlib.ticker.LogLocator(base=10, numticks=7))
        ax.set_title(title, fontsize=10)
        ax.set_xlabel(xlabel, fontsize=8)
        ax.set_ylabel(ylabel, fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6.5, loc="lower left" if stem == "stability_d_still_surface" else "best")
    for k in range(len(panels), rows_n * columns):
        axes[k // columns][k % columns].axis("off")
    fig.suptitle("cfdmpm stability map (issue 14): red crosses are runs that failed; "
                 "vertical lines the measured thresholds", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    fig.savefig(args.out, dpi=110)
    print("stability_map.py: wrote %s (%d panels from %s)" % (args.out, len(panels), ", ".join(dirs)))


if __name__ == "__main__":
    main()
