#!/usr/bin/env python3
"""The Rzadkiewicz submarine slide (input/rzadkiewicz.yaml) in OpenFOAM: mesh, initial fields, results.

Used by utilities/openfoam_slide.sh (which meshes and runs the case); three steps on an OpenFOAM
case directory whose mesh is a uniform blockMesh of the whole tank, cells of size H metres:

  bed CASE H       write constant/polyMesh/sets/fluid, the cells whose centre is not inside the rigid
                   bed (blockMesh's cell order); subsetMesh keeps these (a staircase bed).
  init CASE H      from 0/C (postProcess -func writeCellCentres) write 0/alpha.water, alpha.sand,
                   alpha.air: each cell's volume share of the sand triangle and of the water below
                   y = 1.6 m, from 20 x 20 sample points per cell.
  compare CSV OTHER  eta of an OpenFOAM CSV (from extract) against OTHER, a cfdmpm run's output
                   directory (HDF5, read with utilities/slide_profile.py; needs h5py) or a second
                   OpenFOAM CSV: RMS difference over the columns where both have a surface (OTHER's
                   eta interpolated linearly to the CSV's columns), trough, crest of both and OTHER's
                   front (cfdmpm only), at the times both have.
  extract CASE H   for every written time: the free surface eta(x) and the trough, crest and slide
                   front; writes data/reference/openfoam-rzadkiewicz-<h>mm.csv (time,x,eta) and
                   updates data/reference/openfoam-rzadkiewicz-summary.csv.

Definitions (the same as utilities/slide_profile.py for cfdmpm):
  eta(x): in each column of cells, the topmost cell with alpha.water >= 1/2, its centre moved towards
          the cell above by h (a_j - 1/2)/(a_j - a_above) (linear between cell centres), minus the
          still level 1.6 m. Cells of the bed count as alpha.water = 0. NaN where no cell is wet.
  trough, crest: the smallest and largest eta, at their column centre.
  front:  the largest x at which alpha.sand reaches 1/2 along a row of cells: the centre of the
          rightmost cell with alpha.sand >= 1/2 in its row, moved towards its right neighbour by
          h (a_i - 1/2)/(a_i - a_right); the largest over the rows. (cfdmpm: the largest x of a sand
          particle's centre.)
"""
import argparse
import csv
import datetime
import glob
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import slide_profile  # noqa: E402  (the surface's definition, shared with cfdmpm's outputs)

LOWER = (-2.02, -0.04)
UPPER = (1.5, 2.0)
STILL_LEVEL = 1.6
SAND = np.array([[-0.85, 0.866], [-0.85, 1.5], [-1.486, 1.5]])


def counts(h):
    return int(round((UPPER[0] - LOWER[0]) / h)), int(round((UPPER[1] - LOWER[1]) / h))


def in_bed(x, y, eps=1e-9):
    """The bed polygon [[0,0],[-1.5,1.5],[-2.02,1.5],[-2.02,-0.04],[1.5,-0.04],[1.5,0]] of the yaml
    is {y < 0} + {y < 1.5 and x + y < 0} inside the tank. Points on its boundary (the diagonal row of
    cell centres on the slope) are not inside: the staircase's outer corners lie on the slope."""
    return (y < -eps) | ((y < 1.5 - eps) & (x + y < -eps))


def in_sand(x, y):
    """Inside the sand triangle (gate x = -0.85, top y = 1.5, hypotenuse parallel to the slope)."""
    (x0, y0), (x1, y1), (x2, y2) = SAND
    def side(ax, ay, bx, by):
        return (bx - ax) * (y - ay) - (by - ay) * (x - ax)
    d0, d1, d2 = side(x0, y0, x1, y1), side(x1, y1, x2, y2), side(x2, y2, x0, y0)
    return ((d0 >= 0) & (d1 >= 0) & (d2 >= 0)) | ((d0 <= 0) & (d1 <= 0) & (d2 <= 0))


def foam_header(cls, location, obj):
    return ("FoamFile\n{\n    version     2.0;\n    format      ascii;\n    class       %s;\n"
            "    location    \"%s\";\n    object      %s;\n}\n\n" % (cls, location, obj))


def read_internal(path):
    """The internalField of an ASCII OpenFOAM volField as a numpy array (uniform fields: None)."""
    text = open(path).read()
    m = re.search(r"internalField\s+nonuniform\s+List<(scalar|vector)>\s*(\d+)\s*\(", text)
    if not m:
        m2 = re.search(r"internalField\s+uniform\s+([^;]+);", text)
        if m2:
            return float(m2.group(1)) if m2.group(1).strip()[0] != "(" else None
        sys.exit("openfoam_slide.py: cannot read internalField of " + path)
    n = int(m.group(2))
    body = text[m.end():]
    if m.group(1) == "scalar":
        values = np.array(body.split(None, n)[:n], dtype=float)
    else:
        values = np.array([v.split() for v in re.findall(r"\(([^()]*)\)", body)[:n]], dtype=float)
    if len(values) != n:
        sys.exit("openfoam_slide.py: %s: expected %d values, read %d" % (path, n, len(values)))
    return values


def cell_index(case, h):
    """Column and row (i, j) of every cell of the (subset) mesh, from 0/C."""
    c = read_internal(os.path.join(case, "0", "C"))
    i = np.rint((c[:, 0] - LOWER[0]) / h - 0.5).astype(int)
    j = np.rint((c[:, 1] - LOWER[1]) / h - 0.5).astype(int)
    return c, i, j


def cmd_bed(case, h):
    nx, ny = counts(h)
    j, i = np.divmod(np.arange(nx * ny), nx)  # blockMesh: x fastest
    x = LOWER[0] + h * (i + 0.5)
    y = LOWER[1] + h * (j + 0.5)
    fluid = np.nonzero(~in_bed(x, y))[0]
    os.makedirs(os.path.join(case, "constant", "polyMesh", "sets"), exist_ok=True)
    with open(os.path.join(case, "constant", "polyMesh", "sets", "fluid"), "w") as f:
        f.write(foam_header("cellSet", "constant/polyMesh/sets", "fluid"))
        f.write("%d\n(\n%s\n)\n" % (len(fluid), "\n".join(str(k) for k in fluid)))
    print("bed: %d x %d cells, %d fluid (%d in the bed)" % (nx, ny, len(fluid), nx * ny - len(fluid)))


def write_alpha(case, name, values):
    path = os.path.join(case, "0", name)
    text = open(path).read()
    field = "internalField   nonuniform List<scalar>\n%d\n(\n%s\n)\n;" % (
        len(values), "\n".join("%.10g" % v for v in values))
    text = re.sub(r"internalField\s+uniform\s+0;[^\n]*", lambda _: field, text, count=1)
    open(path, "w").write(text)


def cmd_init(case, h, samples=20):
    c, _, _ = cell_index(case, h)
    offsets = (np.arange(samples) + 0.5) / samples - 0.5
    sx, sy = np.meshgrid(offsets * h, offsets * h)
    sx, sy = sx.ravel(), sy.ravel()
    px = c[:, 0:1] + sx[None, :]
    py = c[:, 1:2] + sy[None, :]
    sand = in_sand(px, py).mean(axis=1)
    below = (py < STILL_LEVEL).mean(axis=1)
    water = np.clip(below - sand, 0.0, 1.0)
    air = np.clip(1.0 - water - sand, 0.0, 1.0)
    write_alpha(case, "alpha.sand", sand)
    write_alpha(case, "alpha.water", water)
    write_alpha(case, "alpha.air", air)
    print("init: %d cells; sand area %.5f m2 (exact %.5f), water area %.5f m2" % (
        len(c), sand.sum() * h * h, 0.5 * (1.5 - 0.866) * (1.486 - 0.85), water.sum() * h * h))


def front(sand, x0, h):
    best = np.nan
    for row in sand:
        full = np.nonzero(row >= 0.5)[0]
        if len(full) == 0:
            continue
        i = full[-1]
        x = x0 + h * (i + 0.5)
        if i + 1 < len(row):
            x += h * (row[i] - 0.5) / (row[i] - row[i + 1])
        best = x if not np.isfinite(best) else max(best, x)
    return best


def log_numbers(case):
    logs = glob.glob(os.path.join(case, "log.multiphaseInterFoam"))
    if not logs:
        return {}
    text = open(logs[0]).read()
    steps = len(re.findall(r"^Time = ", text, re.M))
    times = re.findall(r"ExecutionTime = ([0-9.eE+-]+) s\s+ClockTime = ([0-9.eE+-]+) s", text)
    dts = [float(v) for v in re.findall(r"^deltaT = ([0-9.eE+-]+)", text, re.M)]
    last_time = re.findall(r"^Time = ([0-9.eE+-]+)", text, re.M)
    return dict(steps=steps, cpu=float(times[-1][0]) if times else np.nan,
                wall=float(times[-1][1]) if times else np.nan,
                dt_min=min(dts) if dts else np.nan, dt_max=max(dts) if dts else np.nan,
                end=float(last_time[-1]) if last_time else np.nan,
                completed="\nEnd\n" in text)


def cmd_extract(case, h, out, note, cores=1):
    nx, ny = counts(h)
    _, i, j = cell_index(case, h)
    times = sorted((float(d), d) for d in os.listdir(case)
                   if re.fullmatch(r"[0-9.eE+-]+", d) and os.path.exists(os.path.join(case, d, "alpha.water")))
    rows, summary = [], []
    for t, d in times:
        water = np.zeros((ny, nx))
        sand = np.zeros((ny, nx))
        a = read_internal(os.path.join(case, d, "alpha.water"))
        s = read_internal(os.path.join(case, d, "alpha.sand"))
        water[j, i] = a
        sand[j, i] = s
        x, eta = slide_profile.water_surface(water, LOWER[0], LOWER[1], h, h, STILL_LEVEL)
        k_lo, k_hi = int(np.nanargmin(eta)), int(np.nanargmax(eta))
        rows += [(t, xx, ee) for xx, ee in zip(x, eta)]
        summary.append(dict(time=t, trough=eta[k_lo], trough_x=x[k_lo], crest=eta[k_hi], crest_x=x[k_hi],
                            front=front(sand, LOWER[0], h)))
    info = log_numbers(case)
    mm = "%g" % (h * 1000)
    cells = len(i)
    os.makedirs(out, exist_ok=True)
    path = os.path.join(out, result_name(mm, cores))
    date = datetime.datetime.utcnow().strftime("%Y-%m-%d")
    with open(path, "w", newline="") as f:
        f.write(PROVENANCE.format(
            h=h * 1000, nx=nx, ny=ny, cells=cells, removed=nx * ny - cells, date=date,
            run=RUN_SERIAL if cores == 1 else RUN_PARALLEL.format(cores=cores),
            wall=info.get("wall", np.nan), cpu=info.get("cpu", np.nan), steps=info.get("steps", -1),
            dt_min=info.get("dt_min", np.nan), dt_max=info.get("dt_max", np.nan), end=info.get("end", np.nan),
            completed="ran to the end" if info.get("completed") else "DID NOT FINISH (last time above)",
            note=("# Note: " + note + "\n") if note else ""))
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["time", "x", "eta"])
        for t, xx, ee in rows:
            w.writerow(["%g" % t, "%.6f" % xx, "nan" if not np.isfinite(ee) else "%.6f" % ee])
    print("wrote %s (%d times)" % (path, len(times)))
    # The summary over all resolutions and core counts: this run's (resolution, cores) rows replaced.
    spath = os.path.join(out, "openfoam-rzadkiewicz-summary.csv")
    fields = ["cell_size_mm", "cores", "time", "trough_m", "trough_x", "crest_m", "crest_x", "front_x", "wall_s",
              "cpu_s", "steps"]
    old = [r for r in read_summary(spath) if (r["cell_size_mm"], r["cores"]) != (mm, str(cores))]
    new = [dict(cell_size_mm=mm, cores=str(cores), time="%g" % r["time"], trough_m="%.5f" % r["trough"],
                trough_x="%.4f" % r["trough_x"], crest_m="%.5f" % r["crest"], crest_x="%.4f" % r["crest_x"],
                front_x="%.4f" % r["front"], wall_s="%.0f" % info.get("wall", np.nan),
                cpu_s="%.0f" % info.get("cpu", np.nan), steps=str(info.get("steps", -1))) for r in summary]
    allrows = sorted(old + new, key=lambda r: (int(r["cores"]), -float(r["cell_size_mm"]), float(r["time"])))
    with open(spath, "w", newline="") as f:
        f.write(SUMMARY_HEADER)
        w = csv.DictWriter(f, fieldnames=fields, lineterminator="\n")
        w.writeheader()
        w.writerows(allrows)
    print("%6s %9s %8s %9s %8s %8s" % ("time", "trough_m", "at_x", "crest_m", "at_x", "front_x"))
    for r in summary:
        print("%6.3f %9.5f %8.3f %9.5f %8.3f %8.4f" % (r["time"], r["trough"], r["trough_x"], r["crest"],
                                                       r["crest_x"], r["front"]))
    print("steps %s, wall %s s, cpu %s s" % (info.get("steps"), info.get("wall"), info.get("cpu")))


PROVENANCE = """\
# The Rzadkiewicz et al. (1997) submarine slide of input/rzadkiewicz.yaml run with an independent
# VOF solver: free surface eta(x) = (topmost crossing of alpha.water = 1/2 in each column of cells,
# linear between cell centres) - 1.6 m, at each column centre x, at every written time (seconds).
# Made by utilities/openfoam_slide.sh (case template data/reference/openfoam-rzadkiewicz/,
# extraction utilities/openfoam_slide.py; doc/openfoam-slide.md), on {date} (UTC), on the project's
# 2-core development machine (Debian bookworm),
# {run}.
#   OpenFOAM v1912 (Debian package openfoam 1912.200626-1+b1), multiphaseInterFoam, incompressible,
#   laminar, 2-D (one cell thick, empty front/back), no surface tension.
#   Mesh: uniform square cells h = {h:g} mm, blockMesh {nx} x {ny} of the tank x in [-2.02, 1.5],
#   y in [-0.04, 2.0]; the {removed} cells whose centre lies inside the rigid bed (45 deg slope from
#   the toe (0,0) to the shelf y = 1.5, 4 cm floor) removed with subsetMesh: a staircase bed whose
#   outer corners lie on the slope; {cells} cells. All walls (tank and bed) noSlip, closed tank
#   (pressure level fixed at one point in the air).
#   Phases: water rho 999.8 kg/m3, mu 855e-6 Pa s; air rho 1.27, mu 18.45e-6 Pa s; sand rho 1985,
#   Bingham plastic (HerschelBulkley n = 1): tau0 = 200 Pa (0.100756 m2/s2), plastic viscosity
#   855e-6 Pa s (k = 4.3073e-7 m2/s), viscosity capped at nu0 = 1 m2/s (1985 Pa s) where the
#   strain rate is below 0.1 1/s. Water below y = 1.6, sand triangle
#   [[-0.85,0.866],[-0.85,1.5],[-1.486,1.5]] (volume shares per cell from 20x20 samples), air above;
#   at rest, g = -9.81.
#   Schemes: Euler; div(phi,alpha) Gauss vanLeer, div(phirb,alpha) Gauss linear, MULES cAlpha 1,
#   nAlphaSubCycles 1; div(rhoPhi,U) Gauss linearUpwind grad(U); Gauss linear corrected laplacians;
#   PIMPLE 1 outer / 3 pressure correctors, momentum predictor; p_rgh GAMG (DIC smoother) to 1e-7,
#   U PBiCGStab/DILU to 1e-8;
#   adjustable time step, maxCo = maxAlphaCo = 0.25; to t = 0.8 s, written every 0.1 s.
#   Run: {steps} time steps (dt {dt_min:.3g} .. {dt_max:.3g} s), {completed}, last time {end:g} s;
#   wall (ClockTime) {wall:.0f} s, CPU (ExecutionTime) {cpu:.0f} s.
{note}"""

SUMMARY_HEADER = """\
# The Rzadkiewicz submarine slide in OpenFOAM v1912 multiphaseInterFoam (three phases, Bingham sand of
# yield stress 200 Pa; settings in the per-resolution files openfoam-rzadkiewicz-<h>mm.csv and
# doc/openfoam-slide.md). Per resolution and written time: trough (smallest eta, m) and its x,
# crest (largest eta) and its x, slide front (largest x at which alpha.sand = 1/2 along a row of
# cells, linear between cell centres), wall (ClockTime) and CPU (ExecutionTime) seconds of the
# whole run and its number of time steps, on `cores` cores of the project's 2-core Debian bookworm
# machine (1: a serial run; more: mpirun -np cores, the mesh divided into strips in x of equal cell counts).
"""
RUN_SERIAL = "one core (serial run, nice)"
RUN_PARALLEL = "{cores} cores (mpirun -np {cores} multiphaseInterFoam -parallel; the mesh in strips in x of equal cell counts; nice)"


def result_name(mm, cores):
    """The eta CSV of one run: openfoam-rzadkiewicz-<h>mm.csv (serial) or -<h>mm-<cores>cores.csv."""
    return "openfoam-rzadkiewicz-%smm%s.csv" % (mm, "" if int(cores) == 1 else "-%dcores" % int(cores))


def read_summary(path):
    """The summary's rows; a row written before the cores column (serial runs only) gets cores 1."""
    if not os.path.exists(path):
        return []
    rows = list(csv.DictReader(l for l in open(path) if not l.startswith("#")))
    for r in rows:
        r["cores"] = r.get("cores") or "1"
    return rows


def read_eta_csv(path):
    data = {}
    for r in csv.DictReader(l for l in open(path) if not l.startswith("#")):
        data.setdefault(round(float(r["time"]), 6), []).append((float(r["x"]), float(r["eta"])))
    return data


def cmd_compare(path, other):
    data = read_eta_csv(path)
    if os.path.isfile(other):  # a second OpenFOAM CSV (front: nan, it is not in the CSV)
        runs = {}
        for t, rows in read_eta_csv(other).items():
            x, eta = np.array(rows).T
            lo, hi = int(np.nanargmin(eta)), int(np.nanargmax(eta))
            runs[t] = dict(x=x, eta=eta, trough=eta[lo], trough_x=x[lo], crest=eta[hi], crest_x=x[hi],
                           front=np.nan)
    else:
        args = argparse.Namespace(still_level=STILL_LEVEL, sand_index=1, densities=(1985.0, 999.8))
        runs = {round(r["time"], 6): r for r in slide_profile.profile(other, args)}
    print("%6s %9s | %9s %8s %9s %8s | %9s %8s %9s %8s" % (
        "time", "eta_rms_m", "trough", "at_x", "trough_2", "at_x", "crest", "at_x", "crest_2", "at_x"))
    for t in sorted(set(data) & set(runs)):
        if t == 0:
            continue
        x, eta = np.array(data[t]).T
        r = runs[t]
        rms = slide_profile.eta_rms(x, eta, r["x"], r["eta"])
        lo, hi = int(np.nanargmin(eta)), int(np.nanargmax(eta))
        print("%6.3f %9.5f | %9.5f %8.3f %9.5f %8.3f | %9.5f %8.3f %9.5f %8.3f   front_2 %.4f" % (
            t, rms, eta[lo], x[lo], r["trough"], r["trough_x"], eta[hi], x[hi], r["crest"], r["crest_x"],
            r["front"]))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("step", choices=["bed", "init", "extract", "compare"])
    p.add_argument("case", help="the OpenFOAM case (compare: the OpenFOAM CSV)")
    p.add_argument("h", help="cell size in metres (compare: the cfdmpm output directory)")
    p.add_argument("--out", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data",
                                                 "reference"))
    p.add_argument("--note", default="", help="a line for the CSV header (e.g. why a run stopped)")
    p.add_argument("--cores", type=int, default=1, help="extract: the cores the run used (mpirun -np)")
    a = p.parse_args()
    if a.step == "compare":
        cmd_compare(a.case, a.h)
        return
    a.h = float(a.h)
    if a.step == "bed":
        cmd_bed(a.case, a.h)
    elif a.step == "init":
        cmd_init(a.case, a.h)
    else:
        cmd_extract(a.case, a.h, os.path.normpath(a.out), a.note, a.cores)


if __name__ == "__main__":
    main()
