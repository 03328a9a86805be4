#!/usr/bin/env python3
"""Stability case (i) (doc/stability.md): the time step's Courant number swept on two scenes.

1. The coupled seed scene, input/rzadkiewicz.yaml at 40 mm cells to 0.4 s, time.cfl 0.25 ... 1.0.
   The particles' wave speed sets the step (the fluids' own limit is ~10x larger), so this sweeps
   the particle step's Courant number; the coupled pressure's consistency is measured by the
   equilibration jump (the largest change of a cell's pressure in a step's equilibration, which a
   mismatch between what the pressure equation counted and what the step moved becomes).
2. The fluid step alone: input/dam-break.yaml to 0.25 s, time.cfl 0.25 ... 1.0 with time.dt_max
   lifted, so that the fluids' convective limit sets every step.

Asserts what the project claims of each (doc/stability.md, case i):
- the seed scene at every Courant number up to 0.55 (the default 0.5 and a margin above it) reaches
  0.4 s without a retry;
- the dam break at 0.25 and 0.5 runs without a retry (2-D: with the convective Courant number
  max_d |u_d| Δt / h at most 1/2, no cell loses more than its volume in a step), and at every
  Courant number up to 1 reaches 0.25 s with the water's mass kept to round-off (1e-12 relative);
- a run that is retried or stops names what failed (a cell or a particle, the quantity), never a
  NaN in its output.
Writes stability_i_slide_cfl_np1.csv and stability_i_fluid_cfl_np1.csv (parameter, value, method,
status; thresholds as comment lines) into the working directory or $CFDMPM_STABILITY_DIR.

usage: cfl_sweep.py   (environment: CFDMPM, SOURCE_DIR)
"""
import csv
import os
import re
import statistics
import subprocess
import sys
import tempfile

CFDMPM = os.environ["CFDMPM"]
SOURCE = os.environ["SOURCE_DIR"]
OUT = os.environ.get("CFDMPM_STABILITY_DIR", os.getcwd())

SLIDE_CFLS = [0.25, 0.4, 0.5, 0.55, 0.7, 0.85, 1.0]
FLUID_CFLS = [0.25, 0.5, 0.75, 1.0]
# A named failure: a cell (i, j) or a particle with its id, or the advection's outflux of a cell.
NAMED = re.compile(r"cell \(\d+, \d+|particle \d+")


def scene(template, replacements, work, name):
    text = open(os.path.join(SOURCE, "input", template)).read()
    for old, new in replacements:
        if old not in text:
            sys.exit("cfl_sweep.py: '%s' not found in input/%s" % (old.strip(), template))
        text = text.replace(old, new, 1)
    path = os.path.join(work, name + ".yaml")
    with open(path, "w") as f:
        f.write(text)
    return path


def run(path, work, name):
    """Runs the scene; returns (exit status, log, CSV rows)."""
    result = subprocess.run([CFDMPM, path], capture_output=True, text=True)
    log = result.stdout + result.stderr
    rows = list(csv.DictReader(open(os.path.join(work, name, name + ".csv"))))
    return result.returncode, log, rows


def check_named(name, log, failures):
    """Every retry and the final error name the cell or particle that failed."""
    for line in log.splitlines():
        if " undone: " in line or line.startswith("cfdmpm: error"):
            if not NAMED.search(line):
                failures.append("%s: a failure that names no cell or particle: %s" % (name, line[:300]))


def write_sweep(file_name, rows, thresholds):
    with open(os.path.join(OUT, file_name), "w") as f:
        for label, at in thresholds:
            f.write("# threshold %s = %g\n" % (label, at))
        f.write("parameter,value,method,status\n")
        for parameter, value, method, status in rows:
            f.write('%g,%.6g,"%s",%s\n' % (parameter, value, method, status))


def slide_sweep(work, failures):
    rows, first_failure = [], None
    print("seed scene, 40 mm, to 0.4 s (1 rank)")
    print("  cfl   steps  retries  reached (s)  median / largest equilibration jump (Pa)  limiter of most steps")
    for cfl in SLIDE_CFLS:
        name = "slide_cfl%g" % cfl
        path = scene("rzadkiewicz.yaml", [
            ("directory: output/rzadkiewicz", "directory: " + os.path.join(work, name)),
            ("    cell_size: 0.01 ", "    cell_size: 0.04 "),
            ("    end_time: 0.8", "    end_time: 0.4"),
            ("    cfl: 0.5\n", "    cfl: %g\n" % cfl),
            ("    interval: 0.05", "    interval: 0.4"),
        ], work, name)
        status, log, csv_rows = run(path, work, name)
        check_named(name, log, failures)
        steps = csv_rows[1:]
        jumps = sorted(float(r["equilibration_jump"]) for r in steps)
        undone = log.count(" undone: ")
        limiters = {}
        for r in steps:
            key = r["dt_limiter"].split("+")[0]
            limiters[key] = limiters.get(key, 0) + 1
        reached = float(csv_rows[-1]["time"])
        print("  %-5g %6d  %7d  %11.4f  %12.3g / %-12.3g  %s" % (
            cfl, len(steps), undone, reached, statistics.median(jumps), jumps[-1], max(limiters, key=limiters.get)))
        ok = status == 0 and reached >= 0.4 - 1e-9
        if not ok and first_failure is None:
            first_failure = cfl
        rows.append((cfl, statistics.median(jumps), "cfdmpm: median equilibration jump (Pa)", "ok" if ok else "failed"))
        if cfl <= 0.55 and (undone > 0 or not ok):
            failures.append("seed scene at cfl %g: %d retries, exit status %d, reached %g s (expected none, "
                            "0, 0.4 s)" % (cfl, undone, status, reached))
        if not ok and not log.count("cfdmpm: error"):
            failures.append("seed scene at cfl %g stopped without an error message" % cfl)
    thresholds = [("first failure", first_failure)] if first_failure is not None else []
    write_sweep("stability_i_slide_cfl_np1.csv", rows, thresholds)
    print("  first Courant number that fails: %s" % first_failure)


def fluid_sweep(work, failures):
    rows, first_retry = [], None
    print("dam break, fluid step alone, to 0.25 s (time.dt_max lifted)")
    print("  cfl   steps  retries  water mass change  kinetic energy at 0.25 s (J/m)")
    for cfl in FLUID_CFLS:
        name = "dam_cfl%g" % cfl
        path = scene("dam-break.yaml", [
            ("directory: output/dam-break", "directory: " + os.path.join(work, name)),
            ("    cfl: 0.25", "    cfl: %g" % cfl),
            ("    dt_max: 1.0e-3", "    dt_max: 1.0"),
            ("    interval: 0.01", "    interval: 0.25"),
        ], work, name)
        status, log, csv_rows = run(path, work, name)
        check_named(name, log, failures)
        undone = log.count(" undone: ")
        mass0, mass1 = float(csv_rows[0]["mass_water"]), float(csv_rows[-1]["mass_water"])
        change = abs(mass1 / mass0 - 1.0)
        ke = float(csv_rows[-1]["kinetic_energy_water"])
        reached = float(csv_rows[-1]["time"])
        print("  %-5g %6d  %7d  %17.2e  %.5g" % (cfl, len(csv_rows) - 1, undone, change, ke))
        if undone > 0 and first_retry is None:
            first_retry = cfl
        rows.append((cfl, max(undone, 0.1), "cfdmpm: retried steps (0 drawn at 0.1)", "ok" if status == 0 else "failed"))
        if status != 0 or reached < 0.25 - 1e-9:
            failures.append("dam break at cfl %g: exit status %d, reached %g s" % (cfl, status, reached))
        if change > 1e-12:
            failures.append("dam break at cfl %g: water mass changed by %.3g (bound 1e-12, round-off)" % (cfl, change))
        if cfl <= 0.5 and undone > 0:
            failures.append("dam break at cfl %g: %d retries (expected none at Courant numbers up to 1/2)" % (cfl, undone))
    thresholds = [("first retry", first_retry)] if first_retry is not None else []
    write_sweep("stability_i_fluid_cfl_np1.csv", rows, thresholds)
    print("  first Courant number with a retried step: %s" % first_retry)


def main():
    failures = []
    with tempfile.TemporaryDirectory() as work:
        slide_sweep(work, failures)
        fluid_sweep(work, failures)
    for f in failures:
        print("FAILED: " + f)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
