#!/usr/bin/env python3
"""Check the field files written by test_output_fields (any number of ranks).

    check_output_fields.py <base>      checks <base>_2d.{h5,xmf} and <base>_3d.{h5,xmf}

The HDF5 datasets must hold exactly the values the test program computes, row by global
index, whatever the number of ranks that wrote them; the restart must have replaced the
bogus frame 1; the XDMF must parse, refer to existing datasets with the dimensions and number
types it claims, and carry the frames' total times. Layout: docs/output_format.md.
The expected values (make_mesh, expected_fields, frame_times) are also used by
check_output_paraview.py, which runs in pvpython: h5py is imported only where needed.
"""
import os
import sys
import xml.etree.ElementTree as ET

import numpy as np

FAILURES = []


def check(ok, what):
    if not ok:
        FAILURES.append(what)
        print("FAIL", what)


def make_mesh(ndim):
    """The meshes of output_test_support.f90's make_mesh (global, 0-based rows)."""
    if ndim == 2:
        nx, ny, nz = 5, 4, 0
    else:
        nx, ny, nz = 3, 2, 2
    nxn, nyn = nx + 1, ny + 1
    n_nodes = nxn * nyn * (nz + 1)
    g = np.arange(n_nodes)
    x = np.zeros((n_nodes, 3))
    x[:, 0] = 0.5 * (g % nxn)
    x[:, 1] = 0.25 * ((g // nxn) % nyn)
    if ndim == 3:
        x[:, 2] = 0.125 * (g // (nxn * nyn))
    conn = []
    for k in range(max(nz, 1)):
        for j in range(ny):
            for i in range(nx):
                n0 = i + nxn * j + nxn * nyn * k          # 0-based
                quad = [n0, n0 + 1, n0 + 1 + nxn, n0 + nxn]
                conn.append(quad + ([q + nxn * nyn for q in quad] if ndim == 3 else []))
    return x, np.array(conn, dtype=np.int64)


def expected_fields(ndim, x0, n_elems, f):
    """Values of frame f as test_output_fields.f90 writes them (1-based g, e, c)."""
    n_nodes = x0.shape[0]
    g = np.arange(1, n_nodes + 1, dtype=float)[:, None]
    c = np.arange(1, ndim + 1, dtype=float)[None, :]
    u = g + 0.125 * c + 1000.0 * f
    rf = -0.5 * g * c + 0.25 * f
    pnode = 0.25 * g[:, 0] + f
    coords = x0.copy()
    coords[:, :ndim] += u
    ncomp_s = 4 if ndim == 2 else 6
    e = np.arange(1, n_elems + 1, dtype=float)[:, None]
    cs = np.arange(1, ncomp_s + 1, dtype=float)[None, :]
    s = 10.0 * e + cs + 100.0 * f
    peeq = e[:, 0] / 1024.0 + f
    return {"coordinates": coords, "U": u, "RF": rf, "PNODE": pnode, "S": s, "PEEQ": peeq}


def frame_times(f):
    return {"step": 1 + f, "increment": 10 * f + 3, "step_time": 0.25 * f,
            "total_time": 1.0 / 3.0 + 0.1 * f}


def check_h5(path, ndim):
    import h5py

    x0, conn = make_mesh(ndim)
    n_nodes, n_elems = x0.shape[0], conn.shape[0]
    with h5py.File(path, "r") as h5:
        check(h5.attrs["format"] == b"bulkflow-fields", f"{path}: format attribute")
        check(int(h5.attrs["format_version"]) == 1, f"{path}: format_version")
        mesh = h5["mesh"]
        check(int(mesh.attrs["ndim"]) == ndim, f"{path}: /mesh ndim")
        check(int(mesh.attrs["nen"]) == conn.shape[1], f"{path}: /mesh nen")
        check(mesh.attrs["element_type"] == (b"CPE4R" if ndim == 2 else b"C3D8R"),
              f"{path}: element_type")
        check(np.array_equal(mesh["coordinates"][...], x0), f"{path}: /mesh/coordinates")
        check(np.array_equal(mesh["connectivity"][...], conn), f"{path}: /mesh/connectivity")
        check(mesh["connectivity"].dtype == np.int32, f"{path}: connectivity is int32")
        check(np.array_equal(mesh["node_id"][...], 100 + 3 * np.arange(1, n_nodes + 1)),
              f"{path}: /mesh/node_id")
        check(np.array_equal(mesh["element_id"][...], 1000 + 2 * np.arange(1, n_elems + 1)),
              f"{path}: /mesh/element_id")

        frames = h5["frames"]
        check(sorted(frames.keys()) == ["000000", "000001"], f"{path}: frames {list(frames)}")
        for f in range(2):
            grp = frames.get(f"{f:06d}")
            if grp is None:
                continue
            for key, value in frame_times(f).items():
                check(grp.attrs[key] == value, f"{path}: frame {f} attribute {key} "
                      f"{grp.attrs[key]!r} != {value!r}")
            expected = expected_fields(ndim, x0, n_elems, f)
            # Creation order is kept: the restarted frame 1 lists its fields like frame 0.
            names = list(grp.keys())
            check(sorted(names) == sorted(expected), f"{path}: frame {f} datasets {names}")
            for name, value in expected.items():
                if name not in grp:
                    continue
                data = grp[name][...]
                check(data.shape == value.shape,
                      f"{path}: frame {f} {name} shape {data.shape} != {value.shape}")
                check(data.dtype == np.float64, f"{path}: frame {f} {name} dtype")
                if data.shape == value.shape:
                    bad = np.argwhere(data != value)
                    check(bad.size == 0, f"{path}: frame {f} {name} differs at rows "
                          f"{sorted(set(bad[:, 0].tolist()))[:10]}")
                center = grp[name].attrs["center"]
                want = b"Cell" if name in ("S", "PEEQ") else b"Node"
                check(center == want, f"{path}: frame {f} {name} center {center!r}")


XDMF_NUMBER = {("Float", "8"): np.float64, ("Int", "4"): np.int32}
XDMF_ATTRIBUTE_TYPE = {1: "Scalar", 3: "Vector"}


def check_data_item(item, xmf_dir, where):
    """A DataItem: HDF reference to an existing dataset of the stated shape and type.
    Returns the dataset's numpy array (or None)."""
    import h5py

    if item is None:
        check(False, f"{where}: missing DataItem")
        return None
    check(item.get("Format") == "HDF", f"{where}: Format {item.get('Format')}")
    ref = item.text.strip()
    file_name, _, dataset = ref.partition(":")
    h5_path = os.path.join(xmf_dir, file_name)
    if not os.path.exists(h5_path):
        check(False, f"{where}: HDF5 file {h5_path} missing")
        return None
    with h5py.File(h5_path, "r") as h5:
        if dataset not in h5:
            check(False, f"{where}: dataset {dataset} missing")
            return None
        data = h5[dataset][...]
    dims = tuple(int(d) for d in item.get("Dimensions").split())
    check(dims == data.shape, f"{where}: Dimensions {dims} != dataset shape {data.shape}")
    number = (item.get("NumberType"), item.get("Precision"))
    check(XDMF_NUMBER.get(number) == data.dtype,
          f"{where}: NumberType/Precision {number} for dtype {data.dtype}")
    return data


def check_xmf(path, h5_path, ndim):
    import h5py

    x0, conn = make_mesh(ndim)
    n_nodes, n_elems = x0.shape[0], conn.shape[0]
    xmf_dir = os.path.dirname(os.path.abspath(path))
    root = ET.parse(path).getroot()
    check(root.tag == "Xdmf", f"{path}: root element {root.tag}")
    collection = root.find("Domain/Grid")
    check(collection is not None and collection.get("GridType") == "Collection"
          and collection.get("CollectionType") == "Temporal", f"{path}: temporal collection")
    if collection is None:
        return
    grids = collection.findall("Grid")
    check(len(grids) == 2, f"{path}: {len(grids)} grids, expected 2")
    with h5py.File(h5_path, "r") as h5:
        times = [h5[f"frames/{f:06d}"].attrs["total_time"] for f in range(2)]
    topology_type = "Quadrilateral" if ndim == 2 else "Hexahedron"
    for f, grid in enumerate(grids):
        where = f"{path}: grid {f}"
        check(grid.get("GridType") == "Uniform", f"{where}: GridType")
        time = grid.find("Time")
        check(time is not None and float(time.get("Value")) == times[f],
              f"{where}: Time {None if time is None else time.get('Value')} != {times[f]!r}")
        topology = grid.find("Topology")
        check(topology.get("TopologyType") == topology_type, f"{where}: TopologyType")
        check(int(topology.get("NumberOfElements")) == n_elems, f"{where}: NumberOfElements")
        data = check_data_item(topology.find("DataItem"), xmf_dir, f"{where} topology")
        if data is not None:
            check(np.array_equal(data, conn), f"{where}: topology data")
        geometry = grid.find("Geometry")
        check(geometry.get("GeometryType") == "XYZ", f"{where}: GeometryType")
        item = geometry.find("DataItem")
        check(item.text.strip().endswith(f"/frames/{f:06d}/coordinates"),
              f"{where}: geometry uses the frame's coordinates ({item.text.strip()})")
        check_data_item(item, xmf_dir, f"{where} geometry")
        attributes = grid.findall("Attribute")
        names = [a.get("Name") for a in attributes]
        check(names == ["U", "RF", "PNODE", "S", "PEEQ"], f"{where}: attributes {names}")
        for attribute in attributes:
            name = attribute.get("Name")
            data = check_data_item(attribute.find("DataItem"), xmf_dir, f"{where} {name}")
            if data is None:
                continue
            ncomp = 1 if data.ndim == 1 else data.shape[1]
            check(attribute.get("AttributeType") == XDMF_ATTRIBUTE_TYPE.get(ncomp, "Matrix"),
                  f"{where} {name}: AttributeType {attribute.get('AttributeType')}")
            center = "Cell" if name in ("S", "PEEQ") else "Node"
            check(attribute.get("Center") == center, f"{where} {name}: Center")
            check(data.shape[0] == (n_elems if center == "Cell" else n_nodes),
                  f"{where} {name}: rows")


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    base = sys.argv[1]
    for ndim in (2, 3):
        h5_path = f"{base}_{ndim}d.h5"
        xmf_path = f"{base}_{ndim}d.xmf"
        for p in (h5_path, xmf_path):
            check(os.path.exists(p), f"{p} exists")
        if FAILURES:
            break
        check_h5(h5_path, ndim)
        check_xmf(xmf_path, h5_path, ndim)
        check(not os.path.exists(xmf_path + ".tmp"), f"{xmf_path}.tmp left behind")
    if FAILURES:
        print(f"{len(FAILURES)} failed checks")
        sys.exit(1)
    print("field output OK:", base)


if __name__ == "__main__":
    main()
