#!/usr/bin/env python3
"""Accuracy against cost for the submarine slide (input/rzadkiewicz.yaml): the reference, the table,
the chart and the pictures of doc/validation.md.

  reference DIR LOG   eta(x) of a cfdmpm run (its output directory and the program's log) at every
                      output, as data/reference/cfdmpm-rzadkiewicz-<h>mm.csv (time,x,eta; the format
                      of the OpenFOAM CSVs), with the run's cost and provenance in its header.
  point DIR LOG       one row of data/reference/cfdmpm-rzadkiewicz-runs.csv (replaced if its label is
                      there): --label, --options (the option set, in words), --commit; the run's eta
                      RMS difference from the reference CSV (--reference) at 0.4 and 0.8 s, trough,
                      crest and slide front at both times, wall seconds, steps, retried steps and the
                      time step's most frequent limiter.
  chart               the log-log PNG of eta RMS error against wall time, one point per row of the runs
                      CSV, with OpenFOAM's runs (data/reference/openfoam-rzadkiewicz-*.csv, wall time
                      from its summary; one line per number of cores) measured against the same
                      reference on the same axes.
  table               the runs CSV as a Markdown table (heights in mm, positions in m), for doc/validation.md.
  profiles [LABEL=DIR ...]  eta(x) side by side: the reference, cfdmpm runs, OpenFOAM's 10 and 5 mm runs.
  picture H5          the slide and the wave of one output: the water volume fraction and the
                      particles coloured by speed (the bed's particles grey), as a PNG.

Definitions are those of utilities/slide_profile.py (eta, trough, crest, front), whose functions are
used here. The wall time of a run is read from its log: the last "wall" of each stretch that was not
redone after a restart ("restarted from ...: step S" ends the stretch before it at step S), summed.
Wall times depend on the machine and its load; the table says on how many ranks each run ran.

usage: utilities/slide_chart.py reference DIR LOG [--out CSV] [--note TEXT]
       utilities/slide_chart.py point DIR LOG --label L --options TEXT --commit C [--reference CSV] [--runs CSV]
       utilities/slide_chart.py chart [--runs CSV] [--reference CSV] [--png PNG]
       utilities/slide_chart.py table [--runs CSV]
       utilities/slide_chart.py profiles [LABEL=DIR ...] [--reference CSV] [--png PNG]
       utilities/slide_chart.py picture H5 [--png PNG]
"""
import argparse
import collections
import csv
import datetime
import glob
import itertools
import os
import re
import sys
import textwrap

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import openfoam_slide  # noqa: E402  (read_eta_csv: the format shared with the OpenFOAM CSVs)
import slide_profile  # noqa: E402

REFERENCE = os.path.join(ROOT, "data", "reference", "cfdmpm-rzadkiewicz-5mm.csv")
RUNS = os.path.join(ROOT, "data", "reference", "cfdmpm-rzadkiewicz-runs.csv")
TIMES = (0.4, 0.8)
RUN_COLUMNS = ["label", "options", "cell_size_mm", "ranks", "steps", "retries", "dt_limiter", "wall_s"] + [
    "%s_%g" % (k, t) for t in TIMES for k in ("eta_rms", "trough", "trough_x", "crest", "crest_x", "front")] + [
    "commit"]


def profile_args():
    return argparse.Namespace(still_level=openfoam_slide.STILL_LEVEL, sand_index=1, densities=(1985.0, 999.8))


def log_cost(path):
    """(ranks, wall seconds) of a cfdmpm log, restarts accounted for (see the module's doc)."""
    ranks, total, stretch = None, 0.0, []  # stretch: (step, wall s) of the current run's progress lines
    for line in open(path):
        m = re.search(r"on (\d+) rank\(s\)", line)
        if m and ranks is None:
            ranks = int(m.group(1))
        m = re.search(r"restarted from .*: step (\d+)", line)
        if m:
            kept = [w for s, w in stretch if s <= int(m.group(1))]
            total += kept[-1] if kept else 0.0
            stretch = []
        m = re.match(r"step (\d+) .*wall (\d+):(\d+):(\d+)", line)
        if m:
            stretch.append((int(m.group(1)), 3600 * int(m.group(2)) + 60 * int(m.group(3)) + int(m.group(4))))
    if not stretch:
        sys.exit("slide_chart.py: no progress lines ('step N ... wall H:MM:SS') in " + path)
    return ranks or 1, total + stretch[-1][1]


def diagnostics(directory):
    """(steps, retried steps, most frequent time-step limiter) from a run's CSV."""
    path = glob.glob(os.path.join(directory, "*.csv"))
    if not path:
        sys.exit("slide_chart.py: no diagnostics CSV in " + directory)
    rows = list(csv.DictReader(open(path[0])))
    limiters = collections.Counter(r["dt_limiter"] for r in rows)
    return int(rows[-1]["step"]), sum(int(r["retries"]) > 0 for r in rows), limiters.most_common(1)[0][0]


def cell_size_mm(directory):
    import h5py

    with h5py.File(sorted(glob.glob(os.path.join(directory, "*_[0-9]*.h5")))[0], "r") as f:
        return 1000.0 * float(f["cells"].attrs["spacing_xyz"][0])


def summary(x, eta):
    lo, hi = int(np.nanargmin(eta)), int(np.nanargmax(eta))
    return dict(trough=eta[lo], trough_x=x[lo], crest=eta[hi], crest_x=x[hi])


def reference_profiles(path):
    if not os.path.isfile(path):
        sys.exit("slide_chart.py: no reference CSV %s (make it with: slide_chart.py reference DIR LOG)" % path)
    return {t: tuple(np.array(rows).T) for t, rows in openfoam_slide.read_eta_csv(path).items()}


def cmd_reference(directory, log, out, note):
    runs = slide_profile.profile(directory, profile_args())
    ranks, wall = log_cost(log)
    steps, retries, limiter = diagnostics(directory)
    h = cell_size_mm(directory)
    with open(out, "w", newline="") as handle:
        handle.write(
            "# The submarine slide of input/rzadkiewicz.yaml run by cfdmpm at %g mm cells: the free surface\n"
            "# eta(x) = (topmost crossing of the water volume fraction 1/2 in each column of cells, linear\n"
            "# between cell centres) - 1.6 m, at each column centre x, at every output time (seconds);\n"
            "# utilities/slide_profile.py's definition. Made by utilities/slide_chart.py reference on %s\n"
            "# (UTC) from the run's outputs to t = %g s: %d steps (%d retried), the time step mostly\n"
            "# limited by %s, %d s of wall time on %d MPI rank(s) of the project's 2-core machine.%s\n" % (
                h, datetime.datetime.utcnow().strftime("%Y-%m-%d"), runs[-1]["time"], steps, retries, limiter,
                wall, ranks, "".join("\n# " + line for line in textwrap.wrap(note, 98))))
        writer = csv.writer(handle)
        writer.writerow(["time", "x", "eta"])
        for r in runs:
            for x, eta in zip(r["x"], r["eta"]):
                writer.writerow(["%g" % round(r["time"], 6), "%.6f" % x, "%.6g" % eta])
    print("slide_chart.py: wrote %s (%d outputs, %d s on %d rank(s))" % (out, len(runs), wall, ranks))


def cmd_point(directory, log, a):
    reference = reference_profiles(a.reference)
    runs = {round(r["time"], 6): r for r in slide_profile.profile(directory, profile_args())}
    ranks, wall = log_cost(log)
    steps, retries, limiter = diagnostics(directory)
    row = dict(label=a.label, options=a.options, cell_size_mm="%g" % cell_size_mm(directory), ranks=ranks,
               steps=steps, retries=retries, dt_limiter=limiter, wall_s="%.0f" % wall, commit=a.commit)
    for t in TIMES:  # a time the run or the reference has not reached yet stays empty
        r = runs.get(t)
        if r is None:
            continue
        if t in reference:
            ref_x, ref_eta = reference[t]
            row["eta_rms_%g" % t] = "%.5f" % slide_profile.eta_rms(r["x"], r["eta"], ref_x, ref_eta)
        for k in ("trough", "trough_x", "crest", "crest_x", "front"):
            row["%s_%g" % (k, t)] = "%.4f" % r[k]
    rows = []
    if os.path.isfile(a.runs):
        rows = [r for r in csv.DictReader(l for l in open(a.runs) if not l.startswith("#")) if r["label"] != a.label]
    rows.append(row)
    with open(a.runs, "w", newline="") as handle:
        handle.write("# cfdmpm's runs of the submarine slide (input/rzadkiewicz.yaml) against the 5 mm reference\n"
                     "# (data/reference/cfdmpm-rzadkiewicz-5mm.csv): one row per run, written by\n"
                     "# utilities/slide_chart.py point (definitions there). Lengths in m, times in s.\n")
        writer = csv.DictWriter(handle, RUN_COLUMNS, lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)
    print("slide_chart.py: %s: eta RMS %s m (0.4 s), %s m (0.8 s), %s s wall on %d rank(s)" % (
        a.label, row.get("eta_rms_0.4", "-"), row.get("eta_rms_0.8", "-"), row["wall_s"], ranks))


def openfoam_points(reference):
    """Per OpenFOAM run: (cores, cell size mm, wall s, eta RMS at each of TIMES) against the reference."""
    walls = {}
    path = os.path.join(ROOT, "data", "reference", "openfoam-rzadkiewicz-summary.csv")
    for r in openfoam_slide.read_summary(path):
        walls[(int(r["cores"]), float(r["cell_size_mm"]))] = float(r["wall_s"])
    points = []
    for (cores, h), wall in sorted(walls.items()):
        data = openfoam_slide.read_eta_csv(os.path.join(ROOT, "data", "reference", openfoam_slide.result_name("%g" % h, cores)))
        errors = []
        for t in TIMES:
            if t not in reference:
                errors.append(np.nan)
                continue
            x, eta = np.array(data[t]).T
            ref_x, ref_eta = reference[t]
            errors.append(slide_profile.eta_rms(x, eta, ref_x, ref_eta))
        points.append((cores, h, wall, errors))
    return points


def cmd_chart(a):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    reference = reference_profiles(a.reference)
    rows = list(csv.DictReader(l for l in open(a.runs) if not l.startswith("#")))
    foam = openfoam_points(reference)
    times = [t for t in TIMES if t in reference]  # a reference still running has not reached 0.8 s
    fig, axes = plt.subplots(1, len(times), figsize=(5.5 * len(times) + 0.5, 4.4), sharey=True, squeeze=False)
    axes = axes[0]
    option_sets = sorted({r["options"] for r in rows})
    markers = dict(zip(option_sets, itertools.cycle("osD^v<>phX*P8")))  # any number of option sets
    for ax, t in zip(axes, times):
        for options in option_sets:
            own = sorted((r for r in rows if r["options"] == options), key=lambda r: float(r["wall_s"]))
            # The reference itself has no error, and a run that has not reached t has none yet.
            own = [r for r in own if r["eta_rms_%g" % t] and float(r["eta_rms_%g" % t]) > 0]
            if not own:
                continue
            wall = [float(r["wall_s"]) for r in own]
            error = [1000 * float(r["eta_rms_%g" % t]) for r in own]
            ax.plot(wall, error, marker=markers[options], label="cfdmpm, " + options)
            for r, w, e in zip(own, wall, error):
                ax.annotate("%s mm" % r["cell_size_mm"], (w, e), textcoords="offset points", xytext=(4, 4), fontsize=8)
        for cores, style in zip(sorted({p[0] for p in foam}), itertools.cycle(["k--", "k:"])):
            runs = [p for p in foam if p[0] == cores]
            wall = [p[2] for p in runs]
            error = [1000 * p[3][TIMES.index(t)] for p in runs]
            ax.plot(wall, error, style, marker="x" if cores == 1 else "+",
                    label="OpenFOAM multiphaseInterFoam, Bingham sand (%d core%s)" % (cores, "" if cores == 1 else "s"))
            for p, w, e in zip(runs, wall, error):
                ax.annotate("%g mm" % p[1], (w, e), textcoords="offset points", xytext=(4, -10), fontsize=8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time [s]")
        ax.set_title("t = %g s" % t)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("RMS of eta - eta_ref [mm]")
    # The legend below the panels, in two columns, so that it covers no point however many option
    # sets the runs CSV holds.
    handles, labels = axes[0].get_legend_handles_labels()
    legend_rows = (len(labels) + 1) // 2
    legend_height = 0.22 * legend_rows + 0.3  # inches
    fig.set_figheight(fig.get_figheight() + legend_height)
    fig.legend(handles, labels, loc="lower center", ncol=2, fontsize=8, frameon=False)
    fig.suptitle("Submarine slide (Rzadkiewicz et al. 1997): free-surface error against cost\neta_ref: %s"
                 % os.path.basename(a.reference), fontsize=10)
    fig.tight_layout(rect=(0, legend_height / fig.get_figheight(), 1, 1))
    fig.savefig(a.png, dpi=110)
    print("slide_chart.py: wrote " + a.png)


def cmd_table(a):
    """The runs CSV as the Markdown table of doc/validation.md (heights in mm, positions in m)."""
    rows = list(csv.DictReader(l for l in open(a.runs) if not l.startswith("#")))

    def mm(value):
        return "%.1f" % (1000 * float(value)) if value else "-"

    def m(value):
        return "%.3f" % float(value) if value else "-"

    print("| cells | option set | ranks | eta RMS 0.4 s | trough 0.4 s (x m) | crest 0.4 s | front 0.4 s m "
          "| eta RMS 0.8 s | trough 0.8 s (x m) | crest 0.8 s | front 0.8 s m | wall s | steps (retried) "
          "| Δt limiter | commit |")
    print("|" + "---|" * 15)
    for r in rows:
        cells = []
        for t in TIMES:
            cells += [mm(r["eta_rms_%g" % t]), "%s (%s)" % (mm(r["trough_%g" % t]), m(r["trough_x_%g" % t])),
                      mm(r["crest_%g" % t]), m(r["front_%g" % t])]
        print("| %s mm | %s | %s | %s | %s | %s (%s) | %s | %s |" % (
            r["cell_size_mm"], r["options"], r["ranks"], " | ".join(cells), r["wall_s"], r["steps"], r["retries"],
            r["dt_limiter"], r["commit"]))


def cmd_profiles(a):
    """eta(x) of the reference, of cfdmpm runs given as LABEL=DIR and of OpenFOAM's 10 and 5 mm runs,
    one panel per time of TIMES that the reference has reached."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    reference = reference_profiles(a.reference)
    times = [t for t in TIMES if t in reference]
    curves = [("cfdmpm, reference (%s)" % os.path.basename(a.reference), reference, "k-")]
    for item in a.paths:
        label, directory = item.split("=", 1)
        runs = {round(r["time"], 6): (r["x"], r["eta"]) for r in slide_profile.profile(directory, profile_args())}
        curves.append(("cfdmpm, " + label, runs, "-"))
    for h in (10, 5):
        data = openfoam_slide.read_eta_csv(os.path.join(ROOT, "data", "reference", openfoam_slide.result_name("%g" % h, 1)))
        curves.append(("OpenFOAM, %d mm" % h, {t: tuple(np.array(rows).T) for t, rows in data.items()}, "--"))
    fig, axes = plt.subplots(len(times), 1, figsize=(10, 3.6 * len(times)), squeeze=False)
    for ax, t in zip(axes[:, 0], times):
        for label, data, style in curves:
            if t in data:
                x, eta = data[t]
                ax.plot(x, 1000 * np.asarray(eta), style, label=label, linewidth=1.2)
        ax.set_title("free surface at t = %g s" % t)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("eta [mm]")
        ax.set_xlim(-1.6, 1.5)
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(a.png, dpi=110)
    print("slide_chart.py: wrote " + a.png)


def cmd_picture(path, png):
    import h5py
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with h5py.File(path, "r") as f:
        origin, h = f["cells"].attrs["origin_xyz"], f["cells"].attrs["spacing_xyz"]
        theta = f["cells/water/volume_fraction"][:]
        position = f["particles/position"][:]
        speed = np.linalg.norm(f["particles/velocity"][:], axis=1)
        material = f["particles/material"][:]
        time = float(f.attrs["time"])
    ny, nx = theta.shape
    extent = (origin[0], origin[0] + nx * h[0], origin[1], origin[1] + ny * h[1])
    fig, ax = plt.subplots(figsize=(11, 4.8))
    ax.imshow(theta, origin="lower", extent=extent, cmap="Blues", vmin=0, vmax=1.6, interpolation="nearest")
    bed = material == 0
    size = 0.5 * (72 * 11 / (extent[1] - extent[0]) * h[0]) ** 2 / 4  # ~ a quarter of a cell per particle
    ax.scatter(position[bed, 0], position[bed, 1], s=size, c="0.6", marker="s", linewidths=0)
    sand = ax.scatter(position[~bed, 0], position[~bed, 1], s=size, c=speed[~bed], cmap="inferno", vmin=0,
                      vmax=max(1e-9, speed[~bed].max()), linewidths=0)
    fig.colorbar(sand, ax=ax, label="sand particle speed [m/s]", shrink=0.7)
    ax.set_xlim(extent[0], extent[1])
    ax.set_ylim(0.4, 1.9)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("t = %.2f s, cells of %g mm: water volume fraction (blue), sand by speed, bed (grey)" % (
        time, 1000 * h[0]))
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print("slide_chart.py: wrote " + png)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("command", choices=["reference", "point", "chart", "table", "profiles", "picture"])
    p.add_argument("paths", nargs="*", help="reference/point: DIR LOG; picture: H5; profiles: LABEL=DIR ...")
    p.add_argument("--out", default=REFERENCE, help="reference: the CSV written")
    p.add_argument("--note", default="", help="reference: a line for the CSV's header")
    p.add_argument("--reference", default=REFERENCE)
    p.add_argument("--runs", default=RUNS)
    p.add_argument("--label")
    p.add_argument("--options", default="default scene")
    p.add_argument("--commit", default="")
    p.add_argument("--png")
    a = p.parse_args()
    needed = dict(reference=2, point=2, chart=0, table=0, picture=1).get(a.command)
    if needed is not None and len(a.paths) != needed:
        p.error("%s takes %d path(s), got %d" % (a.command, needed, len(a.paths)))
    if a.command == "reference":
        cmd_reference(a.paths[0], a.paths[1], a.out, a.note)
    elif a.command == "point":
        if not a.label or not a.commit:
            p.error("point needs --label and --commit")
        cmd_point(a.paths[0], a.paths[1], a)
    elif a.command == "table":
        cmd_table(a)
    elif a.command == "profiles":
        a.png = a.png or os.path.join(ROOT, "doc", "img", "rzadkiewicz-profiles.png")
        cmd_profiles(a)
    elif a.command == "chart":
        a.png = a.png or os.path.join(ROOT, "doc", "img", "rzadkiewicz-speed-accuracy.png")
        cmd_chart(a)
    else:
        a.png = a.png or os.path.splitext(os.path.basename(a.paths[0]))[0] + ".png"
        cmd_picture(a.paths[0], a.png)


if __name__ == "__main__":
    main()
