"""pvbatch script: the tutorial's ParaView picture of a blast run (docs/img/).

    pvbatch scripts/paraview_figure.py RUN/run.xdmf OUT.png

Opens run.xdmf as ParaView's GUI would (OpenDataFile), goes to the last frame,
gives every point a vertex (MaskPoints: the reader's points have no cells), keeps
the solids (part > 0: the tube and the rock, not the gas of part 0),
moves the points by their displacement u and colours them by damage, seen from +z.
`make docs-figures` runs it under xvfb-run (scripts/docs_figures.sh).
"""
import sys

import paraview.simple as pv

xdmf, png = sys.argv[1], sys.argv[2]
reader = pv.OpenDataFile(xdmf)
scene = pv.GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
scene.AnimationTime = reader.TimestepValues[-1]

# the reader gives the points without cells: one vertex cell a point, to threshold and draw
points = pv.MaskPoints(Input=reader)
points.OnRatio = 1
points.MaximumNumberofPoints = 1 << 30
points.GenerateVertices = 1
points.SingleVertexPerCell = 1
solids = pv.Threshold(Input=points)
solids.Scalars = ["POINTS", "part"]
solids.LowerThreshold = 0.5
solids.UpperThreshold = 1.0e9
moved = pv.WarpByVector(Input=solids)
moved.Vectors = ["POINTS", "u"]

view = pv.GetActiveViewOrCreate("RenderView")
view.ViewSize = [900, 800]
view.OrientationAxesVisibility = 0
shown = pv.Show(moved, view)
shown.SetRepresentationType("Points")
shown.PointSize = 5.0
pv.ColorBy(shown, ("POINTS", "damage"))
lut = pv.GetColorTransferFunction("damage")
lut.ApplyPreset("Cool to Warm", True)
lut.RescaleTransferFunction(0.0, 1.0)
shown.SetScalarBarVisibility(view, True)
bar = pv.GetScalarBar(lut, view)
bar.Title = "damage"
bar.ComponentTitle = ""

view.CameraPosition = [0.0, 0.0, 0.3]
view.CameraFocalPoint = [0.0, 0.0, 0.003]
view.CameraViewUp = [0.0, 1.0, 0.0]
view.CameraParallelProjection = 1
view.ResetCamera()
pv.Render(view)
pv.SaveScreenshot(png, view, ImageResolution=[900, 800])
print(f"paraview_figure: {png} (t = {reader.TimestepValues[-1] * 1e6:.1f} us)")
