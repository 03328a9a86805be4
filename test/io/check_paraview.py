"""Opens the XDMF time series that io_output wrote with ParaView's readers (run with pvpython) and
checks what a user would see: time steps, bounds in x-y(-z), array names, 3-component vectors and
the values themselves. Argument: the io_output_np<N> directory."""
import sys

from paraview import simple
from paraview import servermanager
from vtkmodules.numpy_interface import dataset_adapter

FAILURES = []


def check(condition, message):
    if not condition:
        FAILURES.append(message)


def known(field, gid, component):
    # knownValue() in io_test_support.hpp
    return 1.0e6 * field + 1.5 * gid + 0.25 * component


def read(reader_name, path, time):
    if reader_name == "XDMFReader":
        reader = simple.XDMFReader(FileNames=[path])
    else:
        reader = getattr(simple, reader_name)(FileName=[path])
    reader.UpdatePipelineInformation()
    times = list(reader.TimestepValues)
    reader.UpdatePipeline(time)
    data = servermanager.Fetch(reader)
    while data.IsA("vtkMultiBlockDataSet"):
        data = data.GetBlock(0)
    return reader, times, data  # the arrays may belong to the reader: keep it until done


def check_run(reader_name, path, times, bounds, cells, nodes):
    where = f"{reader_name} {path}"
    reader, read_times, data = read(reader_name, path, times[-1])
    check(read_times == times, f"{where}: times {read_times}, expected {times}")
    got = data.GetBounds()
    check(all(abs(a - b) < 1e-12 for a, b in zip(got, bounds)), f"{where}: bounds {got}, expected {bounds}")
    wrapped = dataset_adapter.WrapDataObject(data)
    for kind, arrays, count, scalars, vector in (
        ("cell", wrapped.CellData, cells, {"pressure": 1, "water/volume_fraction": 2}, 3),
        ("point", wrapped.PointData, nodes, {}, 4),
    ):
        for name, field in scalars.items():
            check(name in arrays.keys(), f"{where}: no {kind} array {name}")
            if name in arrays.keys():
                values = arrays[name]
                check(values.shape == (count,), f"{where}: {kind} {name} shape {values.shape}")
                check(all(values[g] == known(field, g, 0) for g in range(count)), f"{where}: {kind} {name} values")
        check("velocity" in arrays.keys(), f"{where}: no {kind} array velocity")
        if "velocity" in arrays.keys():
            values = arrays["velocity"]
            check(values.shape == (count, 3), f"{where}: {kind} velocity shape {values.shape}")
            dimension = 3 if bounds[5] > bounds[4] else 2
            for g in range(count):
                expected = [known(vector, g, c) if c < dimension else 0.0 for c in range(3)]
                if list(values[g]) != expected:
                    FAILURES.append(f"{where}: {kind} velocity[{g}] = {list(values[g])}, expected {expected}")
                    break
    simple.Delete(reader)


def main(root):
    # 2-D: 13 x 7 cells from (-1, 0.5) with spacing (0.25, 0.5), in the plane z = 0.
    # The legacy XDMFReader cannot read cell data on a one-node-thick mesh: Xdmf3 readers only.
    for reader in ("Xdmf3ReaderS", "Xdmf3ReaderT"):
        check_run(reader, f"{root}/xdmf_2d/run.xmf", [0.0, 0.05, 0.1], (-1.0, 2.25, 0.5, 4.0, 0.0, 0.0), 91, 112)
    # 3-D: 5 x 4 x 3 cells from (-1, 0.5, 2) with spacing (0.25, 0.5, 0.125): every reader.
    for reader in ("XDMFReader", "Xdmf3ReaderS", "Xdmf3ReaderT"):
        check_run(reader, f"{root}/xdmf_3d/run.xmf", [0.0, 1.0 / 3.0], (-1.0, 0.25, 0.5, 2.5, 2.0, 2.375), 60, 120)
    if FAILURES:
        print("\n".join(FAILURES))
        sys.exit(1)
    print("ParaView reads the 2-D and 3-D series as written")


main(sys.argv[1])
