"""Run by ``pvbatch`` (tests/test_paraview.py), not by pytest: open an XDMF file with
each of ParaView's XDMF readers, go to the last time step, and save what the reader
delivers — time steps, points and every point array — to an .npz.

    pvbatch paraview_probe.py RUN.xdmf OUT.npz

Keys: ``default`` (the reader ParaView picks for the file), ``readers``, and per
reader R: ``R.t`` (its time steps), ``R.x`` (points), ``R.<array>`` (point arrays).
"""
import sys

import numpy as np
from paraview import servermanager, simple
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkDataSet

# reader proxy -> its file-name property
READERS = {"XDMFReader": "FileNames", "Xdmf3ReaderS": "FileName", "Xdmf3ReaderT": "FileName"}


def last_frame(reader):
    steps = reader.TimestepValues
    times = list(steps) if hasattr(steps, "__len__") else [steps]
    reader.UpdatePipeline(times[-1])
    data = servermanager.Fetch(reader)
    if not isinstance(data, vtkDataSet):
        raise SystemExit(f"{reader.GetXMLName()} gave a {data.GetClassName()}, not a data set")
    # copies: the views die with the VTK arrays
    got = {"t": np.array(times), "x": vtk_to_numpy(data.GetPoints().GetData()).copy()}
    pd = data.GetPointData()
    for i in range(pd.GetNumberOfArrays()):
        got[pd.GetArrayName(i)] = vtk_to_numpy(pd.GetArray(i)).copy()
    return got


def main(path, out):
    res = {"default": np.array(simple.OpenDataFile(path).GetXMLName()),
           "readers": np.array(list(READERS))}
    for name, prop in READERS.items():
        reader = getattr(simple, name)(**{prop: [path]})
        for key, a in last_frame(reader).items():
            res[f"{name}.{key}"] = a
        simple.Delete(reader)
    np.savez(out, **res)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
