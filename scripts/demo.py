"""The main job: opens a model with the ReservoirMultiresolution plugin's readers (a GRDECL
deck, or an EGRID such as one `resmr synth` wrote) and writes screenshots (colored by PORO
with cell edges; a deck's faults) to an output folder. Run by `make demo` under a virtual
display when no display is available.

usage: pvpython demo.py PLUGIN MODEL OUTPUT_DIR
"""
import os
import sys

from paraview import servermanager, simple

plugin, deck, output = sys.argv[1:4]
simple.LoadPlugin(plugin, remote=False, ns=vars(simple))
os.makedirs(output, exist_ok=True)

is_deck = not deck.upper().endswith("EGRID")
reader = simple.GRDECLReader(FileName=deck) if is_deck else simple.EGRIDReader(FileName=deck)
prefix = os.path.splitext(os.path.basename(deck))[0]
reader.UpdatePipeline()
reader.UpdatePropertyInformation()
error = reader.GetPropertyValue("LastError")
if error:
    sys.exit(f"demo: cannot read {deck}: {error}")
grid = servermanager.Fetch(reader, arg1=None, arg2=None, idx=0)
print(f"demo: {deck}: {grid.GetCells().GetNumberOfCells()} cells,"
      f" {grid.GetNumberOfPoints()} points, properties {list(reader.CellArrays)}"
      + (f", faults {list(reader.Faults)}" if is_deck else ""))

view = simple.CreateView("RenderView")
view.ViewSize = [1280, 800]
display = simple.Show(simple.OutputPort(reader, 0), view)
display.SetRepresentationType("Surface With Edges")
display.Scale = [1, 1, 8]
simple.ColorBy(display, ("CELLS", "PORO"))
simple.GetColorTransferFunction("PORO").ApplyPreset("Viridis (matplotlib)", True)
display.RescaleTransferFunctionToDataRange(False, True)
display.SetScalarBarVisibility(view, True)
simple.Render(view)
bounds = grid.GetBounds()
centre = [(bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2, 8 * (bounds[4] + bounds[5]) / 2]
size = max(bounds[1] - bounds[0], bounds[3] - bounds[2])
for name, direction in (("oblique", (-0.7, -1.0, 0.8)), ("top", (0.0, -0.05, 1.0))):
    camera = view.GetActiveCamera()
    camera.SetFocalPoint(centre)
    camera.SetPosition([centre[i] + direction[i] * size for i in range(3)])
    camera.SetViewUp(0, 0, 1) if name != "top" else camera.SetViewUp(0, 1, 0)
    view.ResetCamera(False)
    simple.Render(view)
    path = os.path.join(output, f"{prefix}_PORO_{name}.png")
    simple.SaveScreenshot(path, view, ImageResolution=[1280, 800])
    print(f"demo: wrote {path}")

if is_deck:
    faults = simple.Show(simple.OutputPort(reader, 1), view)
    faults.Scale = [1, 1, 8]
    simple.ColorBy(faults, ("CELLS", "FaultIndex"))
    display.Opacity = 0.35
    camera = view.GetActiveCamera()
    camera.SetFocalPoint(centre)
    camera.SetPosition([centre[0] - 0.7 * size, centre[1] - size, centre[2] + 0.8 * size])
    camera.SetViewUp(0, 0, 1)
    view.ResetCamera(False)
    simple.Render(view)
    path = os.path.join(output, f"{prefix}_faults.png")
    simple.SaveScreenshot(path, view, ImageResolution=[1280, 800])
    print(f"demo: wrote {path}")
