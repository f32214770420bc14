"""ParaView reads the XDMF output (run with pvpython, optional test).

    pvpython --force-offscreen-rendering check_output_paraview.py <base>

Opens <base>_2d.xmf and <base>_3d.xmf (written by test_output_fields) with each XDMF reader
ParaView 5.11 has (XDMFReader = Xdmf2, Xdmf3ReaderS/T; OpenDataFile picks Xdmf3ReaderS) and
checks the time steps, the current coordinates of frame 1 and its node and cell arrays,
component order included, against the values check_output_fields.py expects.
Paths are made absolute: Xdmf3 resolves the HDF5 file wrongly for a bare relative name.
"""
import os
import sys

import numpy as np
from paraview import servermanager
from paraview import simple
from paraview.vtk.numpy_interface import dataset_adapter as dsa

sys.dont_write_bytecode = True      # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_output_fields import expected_fields, frame_times, make_mesh  # noqa: E402

FAILURES = []


def check(ok, what):
    if not ok:
        FAILURES.append(what)
        print("FAIL", what)


def open_reader(kind, path):
    if kind == "XDMFReader":
        return simple.XDMFReader(FileNames=[path])
    if kind == "Xdmf3ReaderS":
        return simple.Xdmf3ReaderS(FileName=[path])
    return simple.Xdmf3ReaderT(FileName=[path])


def check_file(path, ndim):
    x0, conn = make_mesh(ndim)
    expected = expected_fields(ndim, x0, conn.shape[0], 1)
    times = [frame_times(f)["total_time"] for f in range(2)]
    check(simple.OpenDataFile(path) is not None, f"{path}: OpenDataFile")
    for kind in ("XDMFReader", "Xdmf3ReaderS", "Xdmf3ReaderT"):
        where = f"{os.path.basename(path)} ({kind})"
        reader = open_reader(kind, path)
        check(list(reader.TimestepValues) == times,
              f"{where}: time steps {list(reader.TimestepValues)} != {times}")
        reader.UpdatePipeline(times[1])
        data = servermanager.Fetch(reader)
        if data.IsA("vtkMultiBlockDataSet"):
            data = data.GetBlock(0)
        grid = dsa.WrapDataObject(data)
        check(data.GetNumberOfPoints() == x0.shape[0], f"{where}: number of points")
        check(data.GetNumberOfCells() == conn.shape[0], f"{where}: number of cells")
        check(np.array_equal(np.asarray(grid.Points), expected["coordinates"]),
              f"{where}: frame 1 points are the current coordinates")
        for name in ("U", "RF", "PNODE"):
            array = grid.PointData[name]
            check(isinstance(array, np.ndarray) and np.array_equal(np.asarray(array), expected[name]),
                  f"{where}: point array {name}")
        for name in ("S", "PEEQ"):
            array = grid.CellData[name]
            check(isinstance(array, np.ndarray) and np.array_equal(np.asarray(array), expected[name]),
                  f"{where}: cell array {name} (VUMAT component order)")
        simple.Delete(reader)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    base = os.path.abspath(sys.argv[1])
    for ndim in (2, 3):
        check_file(f"{base}_{ndim}d.xmf", ndim)
    if FAILURES:
        print(f"{len(FAILURES)} failed checks")
        sys.exit(1)
    print("ParaView reads the field output:", base)


if __name__ == "__main__":
    main()
