#!/usr/bin/python3
"""Accuracy against cost for the dam break: cfdmpm at several cell sizes, a VOF solver for reference.

usage: utilities/speed_accuracy.py [--build build] [--cells 50x20,100x40,200x80] [--png FILE]
                                   [--work DIR] [--json FILE]

Runs input/dam-break.yaml on one MPI rank at each resolution (to t = 0.25 s), measures the surge
front and residual column errors against Martin & Moyce (1952) exactly as utilities/dam_break.py
does, and the CPU seconds the run took (user + system time of the process tree). One rank, because
Open MPI's waiting ranks spin and would count as work. The reference points of another solver come
from data/reference/interfoam-dam-break.csv (measured once, provenance in the file). The chart puts
error on one axis and CPU seconds on the other, so that "faster" and "more accurate" are judged
together. Numbers depend on the machine and its load; compare points measured in the same run.
"""
import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np
import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import dam_break  # noqa: E402


def children_cpu():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run(build, cells, work):
    with open(os.path.join(ROOT, "input", "dam-break.yaml")) as f:
        scene = yaml.safe_load(f)
    body = scene["cfdmpm"]
    body["domain"]["cells"] = list(cells)
    # Patches that divide the grid: the default scene's 25 x 20 for 2.5 mm, smaller for coarser grids.
    body["domain"]["patch_cells"] = [min(25, cells[0]), min(20, cells[1])]
    directory = os.path.join(work, "%dx%d" % cells)
    body["output"]["directory"] = directory
    path = directory + ".yaml"
    with open(path, "w") as f:
        yaml.safe_dump(scene, f, default_flow_style=None, width=100000)  # the form Teuchos reads
    env = dict(os.environ)
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    before, start = children_cpu(), time.perf_counter()
    with open(directory + ".log", "w") as log:
        subprocess.run(["mpiexec", "-n", "1", os.path.join(build, "cfdmpm"), "--overwrite", path],
                       stdout=log, stderr=subprocess.STDOUT, env=env, check=True)
    wall, cpu = time.perf_counter() - start, children_cpu() - before
    t, front, height = dam_break.measure(directory, "water")
    T, Z = t * np.sqrt(2 * dam_break.G / dam_break.A), front / dam_break.A
    tau, H = t * np.sqrt(dam_break.G / dam_break.A), height / (2 * dam_break.A)
    surge, column = dam_break._read("surge-front.csv"), dam_break._read("column-height.csv")
    z = dam_break.compare(T, Z, surge[:, 0], surge[:, 1], 1.0, 3.33)
    h = dam_break.compare(tau, H, column[:, 0], column[:, 1], 0.5, 3.5)
    with open(os.path.join(directory, os.path.basename(directory) + ".csv")) as f:
        steps = sum(1 for _ in f) - 2  # header and step 0
    size = (body["domain"]["upper"][0] - body["domain"]["lower"][0]) / cells[0]
    return {"solver": "cfdmpm", "cell_size_m": size, "cells": cells[0] * cells[1], "steps": steps,
            "cpu_seconds": cpu, "wall_seconds": wall, "surge_front_rms": z["rms"], "column_height_rms": h["rms"]}


def reference_points():
    path = os.path.join(ROOT, "data", "reference", "interfoam-dam-break.csv")
    rows = []
    with open(path) as f:
        lines = [l.strip() for l in f if l.strip() and not l.startswith("#")]
    keys = lines[0].split(",")
    for line in lines[1:]:
        values = line.split(",")
        row = {k: (v if k == "solver" else float(v)) for k, v in zip(keys, values)}
        rows.append(row)
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--cells", default="50x20,100x40,200x80")
    parser.add_argument("--work", help="keep the runs here (default: a temporary directory)")
    parser.add_argument("--png", default="speed-accuracy.png")
    parser.add_argument("--json")
    args = parser.parse_args()
    resolutions = [tuple(int(n) for n in c.split("x")) for c in args.cells.split(",")]

    work = args.work or tempfile.mkdtemp(prefix="cfdmpm-speed-accuracy-")
    os.makedirs(work, exist_ok=True)
    ours = []
    for cells in resolutions:
        r = run(args.build, cells, work)
        ours.append(r)
        print("cfdmpm    %4.1f mm: %6d cells %5d steps  %7.1f CPU s  %5.2f us/cell-step  Z RMS %5.1f %%  H RMS %4.1f %%"
              % (1e3 * r["cell_size_m"], r["cells"], r["steps"], r["cpu_seconds"],
                 1e6 * r["cpu_seconds"] / (r["cells"] * r["steps"]), 100 * r["surge_front_rms"],
                 100 * r["column_height_rms"]), flush=True)
    others = reference_points()
    for r in others:
        print("%-9s %4.1f mm: %6d cells %5d steps  %7.1f CPU s  %5.2f us/cell-step  Z RMS %5.1f %%  H RMS %4.1f %%"
              "  (reference, data/reference)"
              % (r["solver"], 1e3 * r["cell_size_m"], r["cells"], r["steps"], r["cpu_seconds"],
                 1e6 * r["cpu_seconds"] / (r["cells"] * r["steps"]), 100 * r["surge_front_rms"],
                 100 * r["column_height_rms"]))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"cfdmpm": ours, "reference": others}, f, indent=1)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, key, title in zip(axes, ("surge_front_rms", "column_height_rms"),
                              ("surge front Z(T), RMS vs experiment", "residual column H(tau), RMS vs experiment")):
        for name, rows, style in (("cfdmpm (1 core)", ours, "o-"),
                                  ("interFoam v1912 (1 core, reference)", others, "s--")):
            x = [r["cpu_seconds"] for r in rows]
            y = [100 * r[key] for r in rows]
            ax.plot(x, y, style, label=name)
            for r, xi, yi in zip(rows, x, y):
                ax.annotate("%g mm" % (1e3 * r["cell_size_m"]), (xi, yi), textcoords="offset points", xytext=(4, 4))
        ax.set_xscale("log")
        ax.set_xlabel("CPU seconds to t = 0.25 s")
        ax.set_ylabel("relative RMS error (%)")
        ax.set_ylim(bottom=0)
        ax.set_title(title)
        ax.legend()
    fig.tight_layout()
    fig.savefig(args.png, dpi=100)
    print("plot: " + args.png)


if __name__ == "__main__":
    main()
