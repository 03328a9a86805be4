#!/usr/bin/python3
"""Scenes and model of the scaling estimates (doc/scaling.md); bench/scaling.sh runs both.

usage: bench/scaling.py scenes <source dir> <output dir>   writes the scenes the measurements run
       bench/scaling.py model <output dir>                  the estimates from the measurements

The model, per time step of the slowest rank on P ranks (doc/scaling.md, "The model"):

    T(P) = sum over phases of  s_node (a_phase C + b_phase N)                 compute
                             + m_phase(P) alpha + B_phase(P) / beta          halo messages
                             + R_phase(P) t_reduce(P)                        reductions

C and N are the cells and particles of a rank (bench_halos, from METIS on P ranks), the phase's
slowest rank counting (a phase ends with an exchange that waits for it);
a and b the measured seconds per cell and per particle of the phase on one core (two runs that
differ only in particles per cell split them); m and B the messages and bytes of the phase, from
the counts measured on 8 ranks, scaled by the neighbours and ghost cells of the heaviest rank on
P ranks; R the reductions of the phase per step. The network and node figures are assumptions,
stated in ASSUMED below.
"""
import copy
import json
import math
import os
import sys

import yaml

# Assumed machine (doc/scaling.md, "Assumptions"): an InfiniBand HDR100 cluster, 64 cores per node.
ASSUMED = {
    "cores_per_node": 64,
    "latency_s": 2.0e-6,            # an exchange's first message between nodes (0.5 us within one)
    "latency_node_s": 0.5e-6,
    "message_overhead_s": 0.5e-6,   # each further message of an exchange (non-blocking, overlapped)
    "node_bandwidth_Bps": 12.5e9,   # a node's network injection bandwidth, shared by its cores
    "copy_bandwidth_Bps": 5.0e9,    # a message within a node (shared memory copy)
    "reduce_stage_s": 2.0e-6,       # MPI_Allreduce of a few doubles: log2(P) stages of this
    "node_slowdown": 1.5,           # a core of a full node against one core alone (memory bandwidth)
    "iteration_growth": 0.15,       # pressure solve: growth of its exchanges and reductions per
                                    # doubling of P beyond 8 (iterations; MueLu, doc/scaling.md)
}

CELL_PHASES = ["mpmice: 3-6 fluid pressure", "mpmice: 8 exchange", "mpmice: 10 advection"]
PARTICLE_PHASES = ["mpmice: 1 particles to grid", "mpmice: 2 particles to cells", "mpmice: 9 grid to particles",
                   "mpmice: 12 finite", "driver"]
PHASES = PARTICLE_PHASES + CELL_PHASES


class FlowLists(yaml.SafeDumper):
    """Every list in flow style ([a, b] and [[x, y], ...] on one line): the Teuchos YAML reader
    rejects block lists at their key's indentation and flow collections broken over lines."""


FlowLists.add_representer(list, lambda dumper, data: dumper.represent_sequence("tag:yaml.org,2002:seq", data,
                                                                                flow_style=True))


def flow_dump(scene, path):
    with open(path, "w") as f:
        # In the file's order: later regions overwrite earlier ones.
        yaml.dump(scene, f, Dumper=FlowLists, default_flow_style=False, sort_keys=False, width=100000)


def scenes(source, out):
    with open(os.path.join(source, "input", "rzadkiewicz.yaml")) as f:
        slide = yaml.safe_load(f)
    s = slide["cfdmpm"]
    s["time"]["max_steps"] = 12
    s["output"] = {"directory": "OUTPUT", "interval": s["time"]["end_time"], "fields": ["pressure"]}
    for mm in (20, 10, 5):
        t = copy.deepcopy(slide)
        t["cfdmpm"]["domain"]["cell_size"] = mm / 1000  # 176 x 102, 352 x 204, 704 x 408 cells
        flow_dump(t, os.path.join(out, "slide2d_%dmm.yaml" % mm))
        if mm == 10:
            for m in ("bed", "sand"):
                t["cfdmpm"]["materials"][m]["particles_per_cell"] = 3
            flow_dump(t, os.path.join(out, "slide2d_10mm_ppc3.yaml"))
        if mm == 5:
            t["cfdmpm"]["domain"]["rebalance_interval"] = 1
            t["cfdmpm"]["time"]["max_steps"] = 2
            flow_dump(t, os.path.join(out, "slide2d_5mm_rebalance.yaml"))
    # The slide extruded in z: 20 mm cells, 0.2 m wide, walls on both sides as on the others.
    t = copy.deepcopy(slide)
    d = t["cfdmpm"]
    dom = d["domain"]
    dom.update(dimension=3, lower=dom["lower"] + [0.0], upper=dom["upper"] + [0.2], cell_size=0.02,
               patch_cells=[16, 16, 16], gravity=dom["gravity"] + [0.0])
    for region in d["regions"].values():
        if region["shape"] == "half_plane":
            region["point"] = region["point"] + [0.0]
            region["normal"] = region["normal"] + [0.0]
    d["materials"]["bed"]["model"]["velocity"] = d["materials"]["bed"]["model"]["velocity"] + [0.0]
    d["boundary_conditions"]["z-"] = dict(d["boundary_conditions"]["x-"])
    d["boundary_conditions"]["z+"] = dict(d["boundary_conditions"]["x+"])
    flow_dump(t, os.path.join(out, "slide3d_20mm.yaml"))
    for m in ("bed", "sand"):
        d["materials"][m]["particles_per_cell"] = 3
    flow_dump(t, os.path.join(out, "slide3d_20mm_ppc3.yaml"))
    # A dry scene: the granular column (particles alone).
    with open(os.path.join(source, "input", "granular-column.yaml")) as f:
        column = yaml.safe_load(f)
    c = column["cfdmpm"]
    # 0.625 mm cells (153600 cells, 102400 particles): enough work per step for a steady timing.
    c["domain"]["cells"] = [640, 240]
    c["domain"]["patch_cells"] = [40, 40]
    c["time"]["max_steps"] = 52
    c["output"] = {"directory": "OUTPUT", "interval": c["time"]["end_time"], "fields": ["volume_fraction"]}
    flow_dump(column, os.path.join(out, "column.yaml"))
    c["materials"]["sand"]["particles_per_cell"] = 3
    flow_dump(column, os.path.join(out, "column_ppc3.yaml"))


# --- the measurements --------------------------------------------------------------------------


def load(out, name):
    with open(os.path.join(out, name + ".json")) as f:
        return json.load(f)


def fastest(out, name):
    """Per phase, the faster of the runs a and b (seconds per step, slowest rank)."""
    runs = [load(out, "%s_%s" % (name, r)) for r in "ab" if os.path.exists(os.path.join(out, "%s_%s.json" % (name, r)))]
    phases = {}
    for run in runs:
        for phase, v in run["phases"].items():
            phases[phase] = min(phases.get(phase, float("inf")), v["seconds"][0])
    return phases


def csv_column(out, name, column):
    import csv
    with open(os.path.join(out, name, name + ".csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    return [float(r[column]) for r in rows[1:] if r[column] != ""]


def counts_of(out, scene):
    """Cells and particles of a scene's run (from its CSV and log)."""
    particles = csv_column(out, scene, "particles")[-1]
    with open(os.path.join(out, scene + ".log")) as f:
        for line in f:
            if " cells, " in line and "grid " in line:
                dims = line.split("grid ")[1].split(" cells")[0].split(" x ")
                cells = math.prod(int(x) for x in dims)
    return cells, particles


def split_costs(out, base, more, reference):
    """Per phase, a (s per cell-step) and b (s per particle-step) on one core. b from two runs that
    differ only in particles per cell (`base`, `more`); a from `reference` (the grid the estimate is
    for, or the nearest measured) less its particles' share. Phases that touch cells only get b = 0."""
    t1, t2, tr = fastest(out, base + "_np1"), fastest(out, more + "_np1"), fastest(out, reference + "_np1")
    c1, n1 = counts_of(out, base + "_np1_a")
    c2, n2 = counts_of(out, more + "_np1_a")
    cr, nr = counts_of(out, reference + "_np1_a")
    costs = {}
    for phase in PHASES:
        if phase not in tr:
            continue
        b = max(0.0, (t2[phase] - t1[phase]) / (n2 - n1)) if phase in PARTICLE_PHASES else 0.0
        costs[phase] = (max(0.0, (tr[phase] - b * nr) / cr), b)
    return costs, (cr, nr)


def exchange_seconds(ranks, dimension, exchanges, neighbours, byte_count):
    """Halo exchanges of one phase on P ranks: per exchange a latency and an overhead per message,
    and the bytes, the share that leaves the node through the node's network link, the rest
    copied within the node. Ranks are assumed placed so that a node holds a compact block of
    subdomains: the share leaving it is cores^(-1/d) beyond one node."""
    a = ASSUMED
    cores = a["cores_per_node"]
    off_node = 0.0 if ranks <= cores else cores ** (-1.0 / dimension)
    latency = a["latency_node_s"] if ranks <= cores else a["latency_s"]
    per_byte = off_node * cores / a["node_bandwidth_Bps"] + (1 - off_node) / a["copy_bandwidth_Bps"]
    return exchanges * (latency + max(0.0, neighbours - 1) * a["message_overhead_s"]) + byte_count * per_byte


def estimate(h, dim, costs, exchanges, per_ghost, reductions):
    """Compute, exchange and reduction seconds per step of the heaviest rank of halo record h, and
    each phase's seconds."""
    a = ASSUMED
    ranks = h["ranks"]
    growth = 1 + a["iteration_growth"] * math.log2(ranks / 8)
    t_reduce = a["reduce_stage_s"] * math.log2(ranks)
    phase_time = {}
    compute = messages = reduce_time = 0
    for p, (ca, cb) in costs.items():
        g = growth if p == "mpmice: 3-6 fluid pressure" else 1.0
        # The phase ends with an exchange that waits for its slowest rank.
        c = a["node_slowdown"] * max(ca * cells + cb * particles for cells, particles, _, _ in h["per_rank"])
        m = exchange_seconds(ranks, dim, g * exchanges.get(p, 0), h["neighbours"][0],
                             g * per_ghost.get(p, 0) * h["ghosts"][0])
        r = g * reductions.get(p, 0) * t_reduce
        phase_time[p] = c + m + r
        compute, messages, reduce_time = compute + c, messages + m, reduce_time + r
    return compute, messages, reduce_time, phase_time


def steps_to_end(out, name, end_time):
    """Steps of a whole run: the end time over the Δt of the run's last steps."""
    dt = csv_column(out, name, "dt")[-3:]
    return end_time / (sum(dt) / len(dt))


def model(out):
    a = ASSUMED
    print("Assumptions: %s\n" % ", ".join("%s %g" % kv for kv in a.items()))

    # 1. Costs per cell and per particle, phase by phase, on one core.
    costs2, (cells5, particles5) = split_costs(out, "slide2d_10mm", "slide2d_10mm_ppc3", "slide2d_5mm")
    costs3, (cells3d, particles3d) = split_costs(out, "slide3d_20mm", "slide3d_20mm_ppc3", "slide3d_20mm")
    dry, (cells_dry, particles_dry) = split_costs(out, "column", "column_ppc3", "column")
    t5, t3 = fastest(out, "slide2d_5mm_np1"), fastest(out, "slide3d_20mm_np1")
    print("Per-phase cost on one core: us per cell-step (a) and per particle-step (b), and the measured step")
    print("| phase | 2-D a | 2-D b | 2-D 5 mm, ms | 3-D a | 3-D b | 3-D 20 mm, ms |")
    print("|---|---|---|---|---|---|---|")
    for phase in PHASES:
        a2, b2 = costs2.get(phase, (0, 0))
        a3, b3 = costs3.get(phase, (0, 0))
        print("| %s | %.3f | %.3f | %.0f | %.3f | %.3f | %.0f |" % (
            phase.replace("mpmice: ", ""), 1e6 * a2, 1e6 * b2, 1e3 * t5.get(phase, 0), 1e6 * a3, 1e6 * b3,
            1e3 * t3.get(phase, 0)))
    print("| whole step | | | %.0f | | | %.0f |" % (1e3 * sum(t5.values()), 1e3 * sum(t3.values())))
    print("(2-D 5 mm: %d cells, %d particles; 3-D 20 mm: %d cells, %d particles; granular column: %d cells, %d "
          "particles)\n" % (cells5, particles5, cells3d, particles3d, cells_dry, particles_dry))

    def weight(costs):
        return sum(v[1] for v in costs.values()) / sum(v[0] for v in costs.values())
    print("Work of a particle in cells: coupled 2-D %.3f, coupled 3-D %.3f, dry (granular column, 2-D) %.1f\n"
          % (weight(costs2), weight(costs3), weight(dry)))

    # 2. Pressure iterations, and what a rebalance costs.
    print("Pressure solve per step (steps 3-12): outer iterations, CG iterations summed over them")
    for name in ("slide2d_20mm_np1_a", "slide2d_10mm_np1_a", "slide2d_5mm_np1_a", "slide2d_5mm_np2_a",
                 "slide2d_5mm_np4_a", "slide2d_5mm_np8_a", "slide3d_20mm_np1_a", "slide3d_20mm_np8_a"):
        outer = csv_column(out, name, "outer_iterations")[2:]
        cg = csv_column(out, name, "pressure_iterations")[2:]
        print("  %-20s outer %.2f, CG %.2f" % (name, sum(outer) / len(outer), sum(cg) / len(cg)))
    rebalance = load(out, "rebalance_5mm_np2")["phases"].get("cfdmpm: rebalance", {}).get("seconds", [0])[0]
    two = load(out, "slide2d_5mm_np2_a")["phases"]
    step2 = sum(v["seconds"][0] for v in two.values())
    with open(os.path.join(out, "rebalance_5mm_np2.log")) as f:
        moved = [line.strip() for line in f if "patches divided again" in line]
    print("\nA rebalance of the 5 mm slide on 2 ranks: %.2f s (a step there: %.2f s): %s\n"
          % (rebalance, step2, moved[0] if moved else "nothing moved"))

    # 3. Traffic per step, measured on 8 ranks, per exchange and per ghost cell; then the estimates.
    steps2d = steps_to_end(out, "slide2d_5mm_np1_a", 0.8)
    for dim, traffic_name, halo8_file, halos_file, costs, title in (
            (2, "slide2d_5mm_np8_a", "halos_2d.json", "halos_2d.json", costs2, "2-D slide, 5 mm"),
            (3, "slide3d_20mm_np8_a", "halos_3d_20mm.json", "halos_3d.json", costs3, "3-D slide, 5 mm, 1 m wide")):
        traffic = load(out, traffic_name)["phases"]
        with open(os.path.join(out, halo8_file)) as f:
            at8 = next(h for h in json.load(f) if h["ranks"] == 8 and h["weights"] == "cells")
        with open(os.path.join(out, halos_file)) as f:
            halos = json.load(f)
        exchanges = {p: traffic[p]["messages"][0] / at8["neighbours"][0] for p in PHASES if p in traffic}
        per_ghost = {p: traffic[p]["bytes"][0] / at8["ghosts"][0] for p in PHASES if p in traffic}
        reductions = {p: traffic[p]["reductions"][0] + traffic[p]["collectives"][0] for p in PHASES if p in traffic}
        print("%s. Per step, measured on 8 ranks (%s: %d neighbours, %d ghost cells at most):" % (
            title, traffic_name, at8["neighbours"][0], at8["ghosts"][0]))
        print("| phase | halo exchanges | bytes per ghost cell | reductions |")
        print("|---|---|---|---|")
        for p in PHASES:
            if p in traffic:
                print("| %s | %.1f | %.0f | %.1f |" % (p.replace("mpmice: ", ""), exchanges[p], per_ghost[p],
                                                        reductions[p]))
        print()
        print("| ranks | weights | cells | particles | ghosts | neighbours | compute ms | exchanges ms | "
              "reductions ms | step ms | limiting phase (share) | efficiency |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|")
        for h in halos:
            if h["ranks"] < 64:
                continue
            ranks = h["ranks"]
            compute, messages, reduce_time, phase_time = estimate(h, dim, costs, exchanges, per_ghost, reductions)
            step = compute + messages + reduce_time
            serial = sum(ca * h["cells"][1] * ranks + cb * h["particles"][1] * ranks for ca, cb in costs.values())
            limiting = max(phase_time, key=phase_time.get)
            print("| %d | %s | %.0f | %.0f | %.0f | %.0f | %.1f | %.1f | %.2f | %.1f | %s (%.0f %%) | %.2f |" % (
                ranks, h["weights"], h["cells"][0], h["particles"][0], h["ghosts"][0], h["neighbours"][0],
                1e3 * compute, 1e3 * messages, 1e3 * reduce_time, 1e3 * step, limiting.replace("mpmice: ", ""),
                100 * phase_time[limiting] / step, serial / (ranks * step)))
        # How much the estimate on the most ranks depends on each assumption.
        largest = [h for h in halos if h["weights"] == "cells+particles"][-1]
        base = sum(estimate(largest, dim, costs, exchanges, per_ghost, reductions)[:3])
        variants = []
        for key, factor in (("iteration_growth", 0.0), ("iteration_growth", 2.0), ("latency_s", 2.0),
                            ("message_overhead_s", 2.0), ("node_bandwidth_Bps", 0.5), ("reduce_stage_s", 2.0),
                            ("node_slowdown", 1 / 1.5)):
            saved = ASSUMED[key]
            ASSUMED[key] = saved * factor
            variants.append("%s x %g: %.1f ms" % (key, factor, 1e3 * sum(
                estimate(largest, dim, costs, exchanges, per_ghost, reductions)[:3])))
            ASSUMED[key] = saved
        print("Sensitivity on %d ranks (%.1f ms): %s" % (largest["ranks"], 1e3 * base, "; ".join(variants)))
        print("(%.3g cells, %.3g particles; one core: %.2f s per step; 0.8 s of slide: %.3g steps)\n"
              % (h["cells"][1] * ranks, h["particles"][1] * ranks, serial, steps2d))


def main():
    if len(sys.argv) == 4 and sys.argv[1] == "scenes":
        scenes(sys.argv[2], sys.argv[3])
    elif len(sys.argv) == 3 and sys.argv[1] == "model":
        model(sys.argv[2])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
