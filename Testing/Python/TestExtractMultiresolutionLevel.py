"""ExtractMultiresolutionLevel (paper Sec. 4.2, 6.1, 6.2) through its proxy on a .resmr file that
`resmr build` makes from a generated model: the finest level holds every column of the model
(columns x nk hexahedra, its active cells active), coarser levels fewer, an error tolerance
between the levels' errors gives a cut mixing levels, topological coordinates stay in the grid
and each cell spans one layer, a damaged file is refused with its name; and an image of the
coarsest level against its baseline."""
import json
import os
import subprocess

import numpy as np
from paraview import servermanager, simple
from vtkmodules.util.numpy_support import vtk_to_numpy

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
resmr = os.environ["RESMR_EXECUTABLE"]
os.makedirs(args.temp, exist_ok=True)
path = os.path.join(args.temp, "extract.resmr")
NX, NY, NZ = 90, 70, 8
built = subprocess.run([resmr, "build", f"synth:{NX}x{NY}x{NZ}:2", "-o", path, "--cmax", "256", "--quiet"],
                       capture_output=True, text=True, check=True)
report = json.loads(built.stdout)
info = json.loads(subprocess.run([resmr, "info", path], capture_output=True, text=True, check=True).stdout)
levels = info["levels"]
print(f"built {report['regions']} regions on {len(levels)} levels, {report['columns']} columns")
if len(levels) < 3:
    rt.fail(f"expected at least 3 levels, got {len(levels)}")

extract = simple.ExtractMultiresolutionLevel(FileName=path)


def fetch(**properties):
    for name, value in properties.items():
        setattr(extract, name, value)
    extract.UpdatePipeline()
    return servermanager.Fetch(extract)


finest = fetch(Level=len(levels) - 1)
cells = finest.GetNumberOfCells()
active = vtk_to_numpy(finest.GetCellData().GetArray("Active"))
if cells != report["columns"] * NZ or int(active.sum()) != report["active_cells"]:
    rt.fail(f"finest level: {cells} cells, {active.sum()} active; expected {report['columns'] * NZ} and "
            f"{report['active_cells']}")
types = vtk_to_numpy(finest.GetCellTypesArray())
if not np.all(types == 12):
    rt.fail("the output holds cells that are not hexahedra")
topology = vtk_to_numpy(finest.GetPointData().GetArray("TopologicalCoordinates"))
if topology[:, 0].min() < 0 or topology[:, 0].max() > NX or topology[:, 1].max() > NY or topology[:, 2].max() != NZ:
    rt.fail(f"topological coordinates out of range: {topology.min(axis=0)} .. {topology.max(axis=0)}")
connectivity = vtk_to_numpy(finest.GetCells().GetConnectivityArray()).reshape(-1, 8)
if not np.array_equal(topology[connectivity[:, 4:], 2] + 1, topology[connectivity[:, :4], 2]):
    rt.fail("a cell spans more or less than one layer")
if not np.array_equal(topology[connectivity, :2], np.round(topology[connectivity, :2])):
    rt.fail("the finest level has fractional topological coordinates")

by_tolerance = fetch(Level=-1, ErrorTolerance=0.0)
if by_tolerance.GetNumberOfCells() != cells:
    rt.fail(f"tolerance 0 gives {by_tolerance.GetNumberOfCells()} cells, not the finest level's {cells}")
previous = cells
for level in range(len(levels) - 2, -1, -1):
    grid = fetch(Level=level)
    count = grid.GetNumberOfCells()
    if count != levels[level]["columns"] * NZ or count >= previous:
        rt.fail(f"level {level}: {count} cells ({levels[level]['columns']} columns in resmr info, {previous} below)")
    previous = count
middle = 0.5 * (levels[1]["max_error"] + levels[-2]["max_error"])
mixed = fetch(Level=-1, ErrorTolerance=middle)
level_array = vtk_to_numpy(mixed.GetCellData().GetArray("Level"))
print(f"tolerance {middle:.3g}: levels {sorted(set(level_array.tolist()))}, {mixed.GetNumberOfCells()} cells")
if not (levels[0]["columns"] * NZ < mixed.GetNumberOfCells() < cells):
    rt.fail("a middle tolerance should give more cells than the root and fewer than the finest level")

with open(path, "rb") as handle:
    data = bytearray(handle.read())
damaged = os.path.join(args.temp, "damaged.resmr")
with open(damaged, "wb") as handle:
    handle.write(data[: len(data) // 2])
rt.expect_read_error(simple.ExtractMultiresolutionLevel(FileName=damaged), "truncated .resmr", [damaged, "truncated"])

coarsest = fetch(Level=0)
view = simple.CreateRenderView()
view.ViewSize = [800, 600]
view.OrientationAxesVisibility = 0
display = simple.Show(extract, view)
display.Scale = [1.0, 1.0, 5.0]
display.SetRepresentationType("Surface With Edges")
simple.ColorBy(display, ("CELLS", "Region"))
display.RescaleTransferFunctionToDataRange(True)
simple.Render(view)
rt.place_camera(view, coarsest.GetBounds(), 5.0, (1.0, -1.4, 1.2), 1.2)
rt.compare_image(view, args.baselines, "ExtractMultiresolutionLevel_root.png", args.temp)
print("PASS")
