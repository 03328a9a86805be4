"""Checks every .xmf file under a directory with a strict XML parser (xml.etree): well-formed,
root Xdmf/Domain, 3DCoRectMesh topology with matching geometry, and attribute DataItems whose
dimensions agree with the topology (cells = nodes - 1) and whose HDF references name an existing
.h5 file beside the .xmf. A step with particles is a Spatial collection of that grid and a
Polyvertex grid whose XYZ geometry and Node attributes have one row per particle and point into
/particles or /padded/particles. Exits non-zero with a message on the first problem."""
import pathlib
import sys
import xml.etree.ElementTree as ET


def dims(text):
    return [int(x) for x in text.split()]


def check_heavy(item, directory, where, expected, prefixes):
    if item.get("Format") != "HDF":
        return
    file_name, dataset = item.text.strip().split(":", 1)
    assert (directory / file_name).is_file(), (where, file_name)
    assert any(dataset.startswith(p) for p in prefixes), (where, dataset)
    assert dims(item.get("Dimensions")) == expected, (where, dataset, item.get("Dimensions"))


def check_particles(grid, directory, where):
    topology = grid.find("Topology")
    count = int(topology.get("NumberOfElements"))
    prefixes = ("/particles/", "/padded/particles/")
    geometry = grid.find("Geometry")
    assert geometry.get("GeometryType") == "XYZ", where
    check_heavy(geometry.find("DataItem"), directory, where, [count, 3], prefixes)
    for attribute in grid.findall("Attribute"):
        assert attribute.get("Center") == "Node", (where, attribute.get("Name"))
        kind = attribute.get("AttributeType")
        item = attribute.find("DataItem")
        shape = dims(item.get("Dimensions"))
        assert shape[0] == count, (where, attribute.get("Name"))
        assert {"Scalar": 1, "Vector": 2, "Tensor": 2, "Tensor6": 2}.get(kind, len(shape)) == len(shape), where
        if kind == "Vector":
            assert shape[1] == 3, where
        if kind == "Tensor":
            assert shape[1] == 9, where
        check_heavy(item, directory, where, shape, prefixes)
    return 1


def check_grid(grid, directory, where):
    if grid.get("GridType") == "Collection":
        assert grid.get("CollectionType") == "Spatial", where
        children = grid.findall("Grid")
        assert len(children) == 2, where
        assert children[1].find("Topology").get("TopologyType") == "Polyvertex", where
        return check_grid(children[0], directory, where) + check_particles(children[1], directory, where)
    assert grid.get("GridType") == "Uniform", where
    topology = grid.find("Topology")
    geometry = grid.find("Geometry")
    assert topology is not None and geometry is not None, where
    nodes = dims(topology.get("Dimensions"))
    # Always a 3DCoRectMesh; a 2-D grid is one node thick in z.
    assert topology.get("TopologyType") == "3DCoRectMesh" and len(nodes) == 3, where
    assert geometry.get("GeometryType") == "ORIGIN_DXDYDZ", where
    for item in geometry.findall("DataItem"):
        assert len(item.text.split()) == 3, where
    if nodes[0] == 1:
        nodes = nodes[1:]
    cells = [n - 1 for n in nodes]
    for attribute in grid.findall("Attribute"):
        name = attribute.get("Name")
        entries = cells if attribute.get("Center") == "Cell" else nodes
        assert attribute.get("Center") in ("Cell", "Node"), (where, name)
        item = attribute.find("DataItem")
        expected = entries + ([3] if attribute.get("AttributeType") == "Vector" else [])
        assert dims(item.get("Dimensions")) == expected, (where, name, item.get("Dimensions"))
        for heavy in attribute.iter("DataItem"):
            if heavy.get("Format") != "HDF":
                continue
            file_name, dataset = heavy.text.strip().split(":", 1)
            assert (directory / file_name).is_file(), (where, file_name)
            group = "cells/" if attribute.get("Center") == "Cell" else "nodes/"
            assert dataset.startswith("/" + group) or dataset.startswith("/padded/" + group), (where, dataset)
            assert dims(heavy.get("Dimensions")) == expected, (where, name)
    return 1


def main(root):
    files = sorted(pathlib.Path(root).rglob("*.xmf"))
    if not files:
        sys.exit(f"no .xmf files under {root}")
    grids = 0
    for path in files:
        document = ET.parse(path).getroot()
        assert document.tag == "Xdmf", path
        domain = document.find("Domain")
        assert domain is not None, path
        for top in domain.findall("Grid"):
            if top.get("GridType") == "Collection" and top.get("CollectionType") != "Spatial":
                assert top.get("CollectionType") == "Temporal", path
                times = [float(g.find("Time").get("Value")) for g in top.findall("Grid")]
                assert times == sorted(times), (path, times)
                for grid in top.findall("Grid"):
                    grids += check_grid(grid, path.parent, str(path))
            else:
                grids += check_grid(top, path.parent, str(path))
    print(f"{len(files)} XDMF files, {grids} grids: well-formed and consistent")


if __name__ == "__main__":
    main(sys.argv[1])
