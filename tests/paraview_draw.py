"""Run by ``pvbatch`` (tests/test_paraview.py), not by pytest: what ParaView can draw
and filter of an XDMF file at its last time step, saved to an .npz.

    pvbatch paraview_draw.py RUN.xdmf OUT.npz

Keys: ``default`` (the reader ``OpenDataFile`` picks); per reader R of the three and
``open`` (the file opened by ``OpenDataFile``, as the GUI does): ``R.points``,
``R.cells``, ``R.types`` (the distinct VTK cell types), ``R.offsets`` and
``R.connectivity`` (the cells' point ids); for ``open`` also ``threshold`` (points
of Threshold damage >= 0.5), ``threshold_cells``, ``clip`` (cells of a Clip by the
plane x = 0) and ``x`` (the points, to count each side of that plane).
"""
import sys

import numpy as np
from paraview import servermanager, simple
from vtkmodules.util.numpy_support import vtk_to_numpy

READERS = {"XDMFReader": "FileNames", "Xdmf3ReaderS": "FileName", "Xdmf3ReaderT": "FileName"}


def last_time(proxy):
    steps = proxy.TimestepValues
    return list(steps)[-1] if hasattr(steps, "__len__") else steps


def cells(proxy, t, key, res):
    proxy.UpdatePipeline(t)
    data = servermanager.Fetch(proxy)
    res[f"{key}.points"] = data.GetNumberOfPoints()
    res[f"{key}.cells"] = data.GetNumberOfCells()
    ca = data.GetCells()
    res[f"{key}.offsets"] = vtk_to_numpy(ca.GetOffsetsArray()).copy()
    res[f"{key}.connectivity"] = vtk_to_numpy(ca.GetConnectivityArray()).copy()
    res[f"{key}.types"] = np.unique(vtk_to_numpy(data.GetCellTypesArray()))
    return data


def main(path, out):
    opened = simple.OpenDataFile(path)
    res = {"default": np.array(opened.GetXMLName())}
    t = last_time(opened)
    data = cells(opened, t, "open", res)
    res["x"] = vtk_to_numpy(data.GetPoints().GetData()).copy()
    thr = simple.Threshold(Input=opened, Scalars=["POINTS", "damage"],
                           LowerThreshold=0.5, UpperThreshold=1.0e300)
    thr.UpdatePipeline(t)
    info = thr.GetDataInformation()
    res["threshold"], res["threshold_cells"] = info.GetNumberOfPoints(), info.GetNumberOfCells()
    clip = simple.Clip(Input=opened, ClipType="Plane")
    clip.ClipType.Origin, clip.ClipType.Normal = [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]
    clip.UpdatePipeline(t)
    res["clip"] = clip.GetDataInformation().GetNumberOfCells()
    for name, prop in READERS.items():
        reader = getattr(simple, name)(**{prop: [path]})
        cells(reader, last_time(reader), name, res)
        simple.Delete(reader)
    np.savez(out, **res)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
