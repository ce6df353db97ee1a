"""Opens Reek (faulted), Emerald (left-handed, with a hole) and SPE9 (Cartesian) with the
GRDECLReader, renders each colored by PORO with cell edges and compares with baselines that
were looked at. Also checks the Faults output of Reek by name."""
import os

from paraview import servermanager, simple

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
DATA = args.data

CASES = [
    # name, file, vertical exaggeration, camera direction (from focal point), zoom
    ("Reek", "reek/res2df_sim/eclipse/model/2_R001_REEK-0.DATA", 10.0, (-0.6, -1.0, 0.9), 1.5),
    ("Emerald", "emerald/eme_small_w_hole_grid_params.grdecl", 8.0, (0.7, -1.0, 0.9), 1.5),
    ("SPE9", "spe9/opm-data_deck/SPE9.DATA", 3.0, (-0.8, -1.0, 0.8), 1.0),
]

view = simple.CreateView("RenderView")
view.ViewSize = [800, 600]
view.OrientationAxesVisibility = 1

for name, relative, exaggeration, direction, zoom in CASES:
    # Open as the GUI's File > Open does: the reader factory must pick GRDECLReader.
    reader = simple.OpenDataFile(os.path.join(DATA, relative))
    if reader is None or reader.GetXMLName() != "GRDECLReader":
        rt.fail(f"{relative}: ParaView's reader factory did not choose GRDECLReader")
    reader.UpdatePipeline()
    display = simple.Show(reader, view)
    display.SetRepresentationType("Surface With Edges")
    display.Scale = [1.0, 1.0, exaggeration]
    simple.ColorBy(display, ("CELLS", "PORO"))
    lut = simple.GetColorTransferFunction("PORO")
    lut.ApplyPreset("Viridis (matplotlib)", True)
    display.RescaleTransferFunctionToDataRange(False, True)
    display.SetScalarBarVisibility(view, True)
    simple.Render(view)
    # paraview.simple's first Render resets the camera: place it afterwards.
    bounds = servermanager.Fetch(reader, arg1=None, arg2=None, idx=0).GetBounds()
    rt.place_camera(view, bounds, exaggeration, direction, zoom)
    rt.compare_image(view, args.baselines, f"GRDECLReader_{name}_PORO.png", args.temp)
    simple.Hide(reader, view)

    if name == "Reek":
        faults = servermanager.Fetch(reader, arg1=None, arg2=None, idx=1)
        names = faults.GetFieldData().GetAbstractArray("FaultNames")
        fault_names = [names.GetValue(i) for i in range(names.GetNumberOfValues())]
        if fault_names != ["F1", "F2", "F3", "F4", "F5", "F6"]:
            rt.fail(f"Reek fault names {fault_names}")
        quads = faults.GetNumberOfCells()
        index = rt.cell_array(faults, "FaultIndex")
        print(f"Reek faults: {fault_names}, {quads} fault quads")
        if quads < 1000 or index.min() != 0 or index.max() != 5:
            rt.fail(f"Reek faults output has {quads} quads, FaultIndex {index.min()}..{index.max()}")
        reader.Faults = ["F1"]
        reader.UpdatePipeline()
        only_f1 = servermanager.Fetch(reader, arg1=None, arg2=None, idx=1)
        if not (0 < only_f1.GetNumberOfCells() < quads) or rt.cell_array(only_f1, "FaultIndex").max() != 0:
            rt.fail("selecting fault F1 alone did not restrict the Faults output")
        print(f"Reek fault F1 alone: {only_f1.GetNumberOfCells()} quads")
print("PASS")
