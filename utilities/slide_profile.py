#!/usr/bin/env python3
"""The wave and the slide of a submarine-slide run (input/rzadkiewicz.yaml), from its outputs.

For every HDF5 output of a run: the free surface eta(x) (in each column of cells the topmost crossing
of the water volume fraction 1/2, interpolated linearly between cell centres, minus the still water
level), the trough (lowest eta) and the crest (highest eta) with their positions, the slide's front
(the largest x a sand particle's centre reaches), the sand's centre of mass, the kinetic energy of
every material (from the run's CSV at the output's step) and what the sand's descent released (its
buoyant weight times the drop of its centre of mass). With --compare, the RMS difference of eta from
a second run (a reference, e.g. a finer one) at the outputs both runs have, over the columns where both
have a surface.

usage: slide_profile.py OUTPUT_DIR [--compare REFERENCE_DIR] [--eta-csv FILE] [--still-level 1.6]
                        [--sand-index 1] [--densities 1985 999.8]
"""
import argparse
import csv
import glob
import os
import sys

import numpy as np


def read_outputs(directory):
    files = sorted(glob.glob(os.path.join(directory, "*_[0-9]*.h5")))
    if not files:
        sys.exit("slide_profile.py: no HDF5 outputs (*_<step>.h5) in " + directory)
    csvs = glob.glob(os.path.join(directory, "*.csv"))
    rows = {int(r["step"]): r for r in csv.DictReader(open(csvs[0]))} if csvs else {}
    return files, rows


def water_surface(theta, x0, y0, hx, hy, still_level):
    """x of the column centres and eta(x) of a water volume fraction theta (ny, nx) on cells of
    hx by hy whose lower corner is (x0, y0): in each column the topmost cell with theta >= 1/2,
    its centre moved towards the cell above by hy (theta_j - 1/2) / (theta_j - theta_above),
    minus still_level (NaN where a column holds no such cell). utilities/openfoam_slide.py uses
    it too, so that both solvers' surfaces are measured alike."""
    ny, nx = theta.shape
    x = x0 + hx * (np.arange(nx) + 0.5)
    eta = np.full(nx, np.nan)
    for i in range(nx):
        wet = np.nonzero(theta[:, i] >= 0.5)[0]
        if len(wet) == 0:
            continue
        j = wet[-1]
        y = y0 + hy * (j + 0.5)
        if j + 1 < ny:
            above = theta[j + 1, i]
            y += hy * (theta[j, i] - 0.5) / (theta[j, i] - above)
        eta[i] = y - still_level
    return x, eta


def eta_rms(x, eta, ref_x, ref_eta):
    """RMS of eta - ref_eta over the columns x where both have a surface, the reference interpolated
    linearly to x (the grids may differ); NaN where they share none."""
    valid = np.isfinite(ref_eta)
    ref = np.interp(x, ref_x[valid], ref_eta[valid], left=np.nan, right=np.nan)
    both = np.isfinite(ref) & np.isfinite(eta)
    return float(np.sqrt(np.mean((eta[both] - ref[both]) ** 2))) if both.any() else float("nan")


def surface(f, still_level):
    """x of the column centres and eta(x) of an output file (NaN where a column holds no crossing)."""
    origin = f["cells"].attrs["origin_xyz"]
    h = f["cells"].attrs["spacing_xyz"]
    theta = f["cells/water/volume_fraction"][:]  # (ny, nx)
    return water_surface(theta, origin[0], origin[1], h[0], h[1], still_level)


def profile(directory, args):
    import h5py  # only reading outputs needs it (openfoam_slide.py imports this module without)

    files, rows = read_outputs(directory)
    rho_s, rho_w = args.densities
    out = []
    centre0 = None
    for path in files:
        with h5py.File(path, "r") as f:
            time, step = float(f.attrs["time"]), int(f.attrs["step"])
            x, eta = surface(f, args.still_level)
            sand = f["particles/material"][:] == args.sand_index
            position = f["particles/position"][:][sand]
        if len(position) == 0:
            sys.exit("slide_profile.py: no particles of material %d in %s" % (args.sand_index, path))
        centre = position.mean(axis=0)
        if centre0 is None:
            centre0 = centre
        row = rows.get(step, {})
        kinetic = {k: float(row[k]) for k in ("kinetic_energy_water", "kinetic_energy_air", "kinetic_energy_particles")
                   if k in row}
        sand_mass = float(row["mass_sand"]) if "mass_sand" in row else float("nan")
        drop = centre0[1] - centre[1]
        released = (1 - rho_w / rho_s) * sand_mass * 9.81 * drop
        valid = np.isfinite(eta)
        trough = int(np.nanargmin(eta)) if valid.any() else 0
        crest = int(np.nanargmax(eta)) if valid.any() else 0
        out.append(dict(time=time, step=step, x=x, eta=eta, trough=eta[trough], trough_x=x[trough], crest=eta[crest],
                        crest_x=x[crest], front=position[:, 0].max(), centre=centre, kinetic=kinetic,
                        released=released))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("directory")
    parser.add_argument("--compare", help="a reference run's output directory")
    parser.add_argument("--eta-csv", help="write eta(x) of every output to this CSV (one column per time)")
    parser.add_argument("--still-level", type=float, default=1.6, help="still water level [m] (1.6)")
    parser.add_argument("--sand-index", type=int, default=1, help="the sand's material index in the scene (1)")
    parser.add_argument("--densities", type=float, nargs=2, default=(1985.0, 999.8), metavar=("SAND", "WATER"))
    args = parser.parse_args()
    runs = profile(args.directory, args)
    print("%7s %9s %8s %9s %8s %8s %8s %8s %9s %9s %9s" % (
        "time", "trough_m", "at_x", "crest_m", "at_x", "front_x", "centre_x", "centre_y", "kinetic", "released",
        "kin/rel"))
    for r in runs:
        kinetic = sum(r["kinetic"].values()) if r["kinetic"] else float("nan")
        ratio = kinetic / r["released"] if r["released"] > 0 else float("nan")
        print("%7.3f %9.5f %8.3f %9.5f %8.3f %8.4f %8.4f %8.4f %9.3f %9.3f %9.3f" % (
            r["time"], r["trough"], r["trough_x"], r["crest"], r["crest_x"], r["front"], r["centre"][0],
            r["centre"][1], kinetic, r["released"], ratio))
    if args.eta_csv:
        with open(args.eta_csv, "w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(["x"] + ["eta_t%.4f" % r["time"] for r in runs])
            for i, x in enumerate(runs[0]["x"]):
                writer.writerow(["%.6f" % x] + ["%.6g" % r["eta"][i] for r in runs])
    if args.compare:
        reference = {round(r["time"], 6): r for r in profile(args.compare, args)}
        print("\nagainst %s:" % args.compare)
        print("%7s %10s %12s %12s %12s" % ("time", "eta_rms_m", "d_trough_m", "d_trough_x", "d_front_x"))
        for r in runs:
            ref = reference.get(round(r["time"], 6))
            if ref is None:
                continue
            rms = eta_rms(r["x"], r["eta"], ref["x"], ref["eta"])
            print("%7.3f %10.5f %12.5f %12.4f %12.4f" % (r["time"], rms, r["trough"] - ref["trough"],
                                                        r["trough_x"] - ref["trough_x"], r["front"] - ref["front"]))


if __name__ == "__main__":
    main()
