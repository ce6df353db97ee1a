"""Opens Brugge (per-step restarts, field units) and SPE9 (unified restart, 90 steps) as the
GUI does, steps to the last report step with the animation scene, colors by SWAT and
compares with baselines that were looked at. SWAT must change between the first and the
last step (the time toolbar drives the data)."""
import os

import numpy as np
from paraview import servermanager, simple

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
DATA = args.data

CASES = [
    # name, file, report steps, vertical exaggeration, camera direction, zoom
    ("Brugge", "brugge/Real0/BRUGGE_0000.EGRID", 11, 10.0, (-0.5, -1.0, 0.8), 1.4),
    ("SPE9", "spe9/opmflow2022_run_of_opm-data_SPE9_CP/SPE9_CP.EGRID", 90, 3.0, (-0.8, -1.0, 0.8), 1.0),
]

view = simple.CreateView("RenderView")
view.ViewSize = [800, 600]
view.OrientationAxesVisibility = 1
scene = simple.GetAnimationScene()

for name, relative, steps, exaggeration, direction, zoom in CASES:
    reader = simple.OpenDataFile(os.path.join(DATA, relative))
    if reader is None or reader.GetXMLName() != "EGRIDReader":
        rt.fail(f"{relative}: ParaView's reader factory did not choose EGRIDReader")
    scene.UpdateAnimationUsingDataTimeSteps()
    times = list(reader.TimestepValues)
    if len(times) != steps:
        rt.fail(f"{name}: {len(times)} time steps on the animation toolbar, expected {steps}")
    display = simple.Show(reader, view)
    scene.GoToFirst()
    reader.UpdatePipeline(view.ViewTime)
    first = rt.cell_array(servermanager.Fetch(reader, arg1=None, arg2=None, idx=0), "SWAT").copy()
    scene.GoToLast()  # as the time toolbar's "last frame" button
    reader.UpdatePipeline(view.ViewTime)
    grid = servermanager.Fetch(reader, arg1=None, arg2=None, idx=0)
    last = rt.cell_array(grid, "SWAT")
    shown = grid.GetFieldData().GetArray("Days").GetValue(0)
    if shown != times[-1]:
        rt.fail(f"{name}: last step shows day {shown}, expected {times[-1]}")
    changed = np.nansum(np.abs(last - first) > 1e-3)
    print(f"{name}: {len(times)} steps, day {shown}: SWAT changed in {changed} cells since day {times[0]}")
    if changed < 100:
        rt.fail(f"{name}: SWAT barely changes between the first and the last step")

    display.SetRepresentationType("Surface With Edges")
    display.Scale = [1.0, 1.0, exaggeration]
    simple.ColorBy(display, ("CELLS", "SWAT"))
    lut = simple.GetColorTransferFunction("SWAT")
    lut.ApplyPreset("Blue Orange (divergent)", True)
    lut.RescaleTransferFunction(0.0, 1.0)
    display.SetScalarBarVisibility(view, True)
    simple.Render(view)
    bounds = grid.GetBounds()
    rt.place_camera(view, bounds, exaggeration, direction, zoom)
    rt.compare_image(view, args.baselines, f"EGRIDReader_{name}_SWAT_last.png", args.temp)
    simple.Hide(reader, view)
    simple.Delete(reader)
print("EGRID reader images match")
