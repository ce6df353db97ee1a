"""SimplifyReservoirGrid (paper Sec. 4.1) through its proxy on Reek: an all-hexahedra
unstructured grid of whole columns of nk cells, the requested column count, no inverted cell
(ParaView's own Mesh Quality, scaled Jacobian), topological coordinates inside the original
ranges with tk the layer interface, the same mesh for the same seed and another for another
seed; a grid without active cells refused with a clear message; and an image of the
simplified Reek against its baseline."""
import os

import numpy as np
from paraview import servermanager, simple
from vtkmodules.util.numpy_support import vtk_to_numpy

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
REEK = os.path.join(args.data, "reek/res2df_sim/eclipse/model/2_R001_REEK-0.EGRID")
NX, NY, NZ = 40, 64, 14

reader = simple.EGRIDReader(FileName=REEK)
simplified = simple.SimplifyReservoirGrid(Input=reader, TargetFraction=0.5, Seed=3)
simplified.UpdatePipeline()
grid = servermanager.Fetch(simplified)
field = grid.GetFieldData()
before = field.GetArray("ColumnsBefore").GetValue(0)
after = field.GetArray("ColumnsAfter").GetValue(0)
print(f"Reek: {before:.0f} -> {after:.0f} columns, {grid.GetNumberOfCells()} cells, "
      f"{field.GetArray('Collapses').GetValue(0):.0f} collapses")
if before != 2560 or after != 1280 or field.GetArray("ReachedTarget").GetValue(0) != 1:
    rt.fail(f"expected 2560 -> 1280 columns, got {before} -> {after}")
if grid.GetNumberOfCells() != after * NZ:
    rt.fail(f"{grid.GetNumberOfCells()} cells is not {after:.0f} columns of {NZ}")
types = vtk_to_numpy(grid.GetCellTypesArray())
if not np.all(types == 12):  # VTK_HEXAHEDRON
    rt.fail("the output holds cells that are not hexahedra")

topology = vtk_to_numpy(grid.GetPointData().GetArray("TopologicalCoordinates"))
if (topology[:, 0].min() < 0 or topology[:, 0].max() > NX or topology[:, 1].min() < 0 or
        topology[:, 1].max() > NY or not np.array_equal(topology[:, 2], np.round(topology[:, 2])) or
        topology[:, 2].max() != NZ):
    rt.fail(f"topological coordinates out of range: {topology.min(axis=0)} .. {topology.max(axis=0)}")
# Each cell spans one layer: tk of its upper face is one less than of its lower face.
connectivity = vtk_to_numpy(grid.GetCells().GetConnectivityArray()).reshape(-1, 8)
if not np.array_equal(topology[connectivity[:, 4:], 2] + 1, topology[connectivity[:, :4], 2]):
    rt.fail("a cell spans more or less than one layer")

quality = simple.MeshQuality(Input=simplified, HexQualityMeasure="Scaled Jacobian")
quality.UpdatePipeline()
measured = vtk_to_numpy(servermanager.Fetch(quality).GetCellData().GetArray("Quality"))
inverted = int(np.sum(measured < -1e-9))
measurable = measured[measured <= 1.0]  # VTK gives degenerate (pinched-out) cells a huge value
print(f"scaled Jacobian: min {measured.min():.4f}, mean {measurable.mean():.4f}, {inverted} inverted, "
      f"{measured.size - measurable.size} degenerate")
if inverted:
    rt.fail(f"{inverted} inverted hexahedra after simplification")

points = vtk_to_numpy(grid.GetPoints().GetData()).copy()
simplified.Seed = 3
simplified.TargetColumns = 1280
simplified.UpdatePipeline()
if not np.array_equal(vtk_to_numpy(servermanager.Fetch(simplified).GetPoints().GetData()), points):
    rt.fail("the same seed gave another mesh")
simplified.Seed = 4
simplified.UpdatePipeline()
if np.array_equal(vtk_to_numpy(servermanager.Fetch(simplified).GetPoints().GetData()), points):
    rt.fail("seeds 3 and 4 gave the same mesh")

# No active cell: refused with a message, nothing crashes.
deck = os.path.join(args.temp, "all_inactive.grdecl")
os.makedirs(args.temp, exist_ok=True)
with open(deck, "w") as handle:
    handle.write("SPECGRID\n2 2 1 1 F /\nDX\n4*10 /\nDY\n4*10 /\nDZ\n4*1 /\nTOPS\n4*1000 /\n"
                 "ACTNUM\n4*0 /\n")
empty = simple.SimplifyReservoirGrid(Input=simple.GRDECLReader(FileName=deck))
empty.UpdatePipeline()
empty.UpdatePropertyInformation()
message = empty.GetPropertyValue("LastError")
if "no active cell" not in message:
    rt.fail(f"all-inactive grid: {message!r}")
print(f"all-inactive grid: {message}")

# The image: Reek at a quarter of its columns, coloured by the interpolated I coordinate.
simplified.TargetColumns = 0
simplified.TargetFraction = 0.25
simplified.Seed = 1
view = simple.CreateView("RenderView")
view.ViewSize = [800, 600]
view.OrientationAxesVisibility = 1
display = simple.Show(simplified, view)
display.SetRepresentationType("Surface With Edges")
display.Scale = [1.0, 1.0, 5.0]
simple.ColorBy(display, ("POINTS", "TopologicalCoordinates", "X"))
lut = simple.GetColorTransferFunction("TopologicalCoordinates")
lut.VectorMode = "Component"
lut.VectorComponent = 0
lut.RescaleTransferFunction(0.0, float(NX))
simple.Render(view)
rt.place_camera(view, servermanager.Fetch(simplified).GetBounds(), 5.0, (-0.6, -1.0, 0.9), 1.3)
rt.compare_image(view, args.baselines, "SimplifyReservoirGrid_Reek_25.png", args.temp)
print("simplification checks passed")
