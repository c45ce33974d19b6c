"""A damage picture of any mpipd run, drawn by ParaView (pvbatch or pvpython).

    pvbatch scripts/paraview_figure.py RUN [--out PNG] [--frame K] [--threshold D]
            [--field NAME] [--parts NAME,NAME | --all-parts] [--warp S] [--view V]
            [--size W H] [--point-size PX]

RUN is a run folder, its run.h5 or its run.xdmf.  The script opens run.xdmf as
ParaView's GUI does (``OpenDataFile``: the reader it picks, Xdmf3ReaderS), goes to
frame K (default -1, the last; 0 is the first), keeps the solid parts (the explosive's
gas points are hidden: run.xdmf names each part and says which is gas; ``--parts``
names the parts to show, ``--all-parts`` shows all), moves every point by its
displacement times S (Warp By Vector with ``u``; default 1, the true shape; 0 keeps
the reference positions) and colours the points by damage (0 blue to 1 red).  With
``--threshold D`` only the points with damage >= D are coloured (a Threshold on
damage), the other points of the shown parts are drawn light grey behind them.  The
view looks down V (+z, the default: from +z towards -z; -z, +x, -x, +y, -y, or iso),
in parallel projection.  PNG defaults to RUN/paraview_damage.png.

Headless, Debian's ParaView renders only through X (no offscreen build): give it a
virtual display, ``bash scripts/docs_figures.sh RUN PNG [options]`` (an Xvfb of its
own and a clean environment) or ``xvfb-run -a pvbatch ...``;
scripts/install_paraview.sh installs ParaView and xvfb.  pvbatch embeds the system
Python: do not run it with the venv's PYTHONPATH.

Every point of run.xdmf is a vertex cell (mpipd.output.writer.write_xdmf), so the
reader's output draws and filters as it is.  A run.xdmf written before that (its
readers give the points and no cell) still works: Mask Points gives each point a
vertex first; such a file lists no parts, so all are shown.

It prints one line: the frame and time, the reader with its points and cells, the
points shown and, with ``--threshold``, the points at or above it.
"""
import argparse
import json
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import paraview.simple as pv

VIEWS = {"+z": ((0, 0, 1), (0, 1, 0)), "-z": ((0, 0, -1), (0, 1, 0)),
         "+x": ((1, 0, 0), (0, 0, 1)), "-x": ((-1, 0, 0), (0, 0, 1)),
         "+y": ((0, 1, 0), (0, 0, 1)), "-y": ((0, -1, 0), (0, 0, 1)),
         "iso": ((1, -1, 1), (0, 0, 1))}
GREY = [0.78, 0.78, 0.78]


def parse(argv):
    ap = argparse.ArgumentParser(prog="paraview_figure.py", description=__doc__.split("\n")[0])
    ap.add_argument("run", help="a run folder, its run.h5 or its run.xdmf")
    ap.add_argument("--out", help="the PNG (default RUN/paraview_damage.png)")
    ap.add_argument("--frame", type=int, default=-1,
                    help="frame index, 0 the first, negative from the end (default -1: the last)")
    ap.add_argument("--field", default="damage", help="the point field that colours (default damage)")
    ap.add_argument("--threshold", type=float, default=None,
                    help="colour only the points with FIELD >= this; the rest drawn grey")
    ap.add_argument("--parts", help="comma-separated names of the parts to show "
                                    "(default: every part but an explosive's gas)")
    ap.add_argument("--all-parts", action="store_true", help="show every part, the gas too")
    ap.add_argument("--warp", type=float, default=1.0,
                    help="scale of the displacement u added to the positions (default 1; 0: none)")
    ap.add_argument("--view", choices=sorted(VIEWS), default="+z",
                    help="look down this axis (default +z: the x-y plane seen from above)")
    ap.add_argument("--size", type=int, nargs=2, default=(1000, 800), metavar=("W", "H"))
    ap.add_argument("--point-size", type=float, default=4.0, help="pixels (default 4)")
    return ap.parse_args(argv)


def xdmf_of(run: str) -> Path:
    p = Path(run)
    if p.is_dir():
        p = p / "run.xdmf"
    elif p.suffix != ".xdmf":
        p = p.with_suffix(".xdmf")
    if not p.is_file():
        raise SystemExit(f"paraview_figure: no {p} (mpipd writes run.xdmf beside run.h5 "
                         "when a run ends or stops)")
    return p.resolve()


def part_table(xdmf: Path) -> list:
    """The parts as run.xdmf lists them (index -> name, material, gas); [] for a file
    written before it did."""
    for ev, el in ET.iterparse(xdmf, events=("start",)):
        if el.tag == "Information" and el.get("Name") == "parts":
            return json.loads(el.get("Value"))
        if el.tag == "Grid":             # the Information comes before the first grid
            return []
    return []


def kept_parts(table, names, every) -> list | None:
    """Part indices to show, or None for all of them."""
    if every:
        return None
    if names:
        want = [n.strip() for n in names.split(",") if n.strip()]
        known = [q["name"] for q in table]
        bad = [n for n in want if n not in known]
        if bad:
            raise SystemExit(f"paraview_figure: no part {', '.join(bad)} in this run "
                             f"(its parts: {', '.join(known) or 'not listed in run.xdmf'})")
        return [i for i, q in enumerate(table) if q["name"] in want]
    keep = [i for i, q in enumerate(table) if not q.get("gas")]
    return None if len(keep) == len(table) else keep


def point_arrays(proxy) -> list:
    return list(proxy.PointData.keys())


def main(argv):
    a = parse(argv)
    xdmf = xdmf_of(a.run)
    out = Path(a.out).resolve() if a.out else xdmf.parent / "paraview_damage.png"
    table = part_table(xdmf)

    reader = pv.OpenDataFile(str(xdmf))
    steps = reader.TimestepValues
    steps = list(steps) if hasattr(steps, "__len__") else [steps]
    if not -len(steps) <= a.frame < len(steps):
        raise SystemExit(f"paraview_figure: no frame {a.frame}: the run has {len(steps)} "
                         f"(0 .. {len(steps) - 1})")
    k = a.frame % len(steps)
    t = steps[k]
    scene = pv.GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    scene.AnimationTime = t
    reader.UpdatePipeline(t)
    info = reader.GetDataInformation()
    n_points, n_cells = info.GetNumberOfPoints(), info.GetNumberOfCells()
    if a.field not in point_arrays(reader):
        raise SystemExit(f"paraview_figure: the run has no field {a.field!r} "
                         f"(it has {', '.join(sorted(point_arrays(reader)))})")
    shown, names, note = reader, "all parts", ""
    if n_cells == 0:     # a run.xdmf from before its Polyvertex had a connectivity
        shown = pv.MaskPoints(Input=reader, OnRatio=1, MaximumNumberofPoints=(1 << 31) - 1,
                              GenerateVertices=1, SingleVertexPerCell=1, RandomSampling=0)
        note = " (an older run.xdmf without vertex cells: Mask Points gave them)"
    keep = kept_parts(table, a.parts, a.all_parts)
    if keep is not None:
        mask = pv.PythonCalculator(Input=shown, ArrayName="shown_part",
                                   Expression=f"numpy.isin(inputs[0].PointData['part'], {keep})"
                                              ".astype(numpy.float64)")
        shown = pv.Threshold(Input=mask, Scalars=["POINTS", "shown_part"],
                             LowerThreshold=0.5, UpperThreshold=1.5)
        names = ", ".join(table[i]["name"] for i in keep)
    if a.warp != 0 and "u" in point_arrays(reader):
        shown = pv.WarpByVector(Input=shown, Vectors=["POINTS", "u"], ScaleFactor=a.warp)
    shown.UpdatePipeline(t)
    n_shown = shown.GetDataInformation().GetNumberOfPoints()

    view = pv.GetActiveViewOrCreate("RenderView")
    view.ViewSize = list(a.size)
    view.OrientationAxesVisibility = 0
    view.Background = [1.0, 1.0, 1.0]
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    lut = pv.GetColorTransferFunction(a.field)
    lut.ApplyPreset("Cool to Warm", True)
    lut.AutomaticRescaleRangeMode = "Never"      # the whole range, thresholded or not
    if a.field == "damage":
        lo, hi = 0.0, 1.0
    else:                                       # a vector or tensor: its magnitude
        arr = shown.PointData[a.field]
        lo, hi = arr.GetRange(0 if arr.GetNumberOfComponents() == 1 else -1)
    coloured, line = shown, ""
    if a.threshold is not None:
        rest = pv.Threshold(Input=shown, Scalars=["POINTS", a.field], Invert=1,
                            LowerThreshold=a.threshold, UpperThreshold=1.0e300)
        rest = pv.Show(rest, view)
        rest.SetRepresentationType("Points")
        rest.PointSize = a.point_size
        rest.ColorArrayName = ["POINTS", ""]            # one colour
        rest.AmbientColor = rest.DiffuseColor = GREY
        coloured = pv.Threshold(Input=shown, Scalars=["POINTS", a.field],
                                LowerThreshold=a.threshold, UpperThreshold=1.0e300)
        coloured.UpdatePipeline(t)
        n_hot = coloured.GetDataInformation().GetNumberOfPoints()
        line = f"; {a.field} >= {a.threshold:g}: {n_hot} points"
    drawn = pv.Show(coloured, view)
    drawn.SetRepresentationType("Points")
    drawn.PointSize = a.point_size
    pv.ColorBy(drawn, ("POINTS", a.field))
    lut.RescaleTransferFunction(lo, hi)
    drawn.SetScalarBarVisibility(view, True)
    bar = pv.GetScalarBar(lut, view)
    bar.Title = a.field
    bar.ComponentTitle = ""
    bar.TitleColor = bar.LabelColor = [0.1, 0.1, 0.1]

    d, up = VIEWS[a.view]
    view.CameraFocalPoint = [0.0, 0.0, 0.0]
    view.CameraPosition = list(d)
    view.CameraViewUp = list(up)
    view.CameraParallelProjection = 1
    view.ResetCamera()
    pv.Render(view)
    out.parent.mkdir(parents=True, exist_ok=True)
    pv.SaveScreenshot(str(out), view, ImageResolution=list(a.size))
    print(f"paraview_figure: {out}: frame {k} of {len(steps)} (t = {t * 1e6:.3g} us), "
          f"{reader.GetXMLName()} {n_points} points {n_cells} cells{note}; shown ({names}, "
          f"warp {a.warp:g}, view {a.view}): {n_shown} points{line}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
