"""MultiresolutionReader (issue 7, paper Sec. 6): File > Open on a .resmr gives a descriptor, not
cells. On SPE9 (an OPM Flow run) built with `resmr build` and `resmr add-properties`: the reader
is the one the open dialog picks; its output is the model's box (8 points, 12 edges, z up) equal
to the EGRID's bounds; its time steps are the restart's report steps; each property's array
holds the simulator's minimum and maximum at the requested step (checked against EGRIDReader on
the same run); a truncated file and a property file of another geometry are refused by name."""
import json
import math
import os
import shutil
import subprocess

import numpy as np
from paraview import servermanager, simple
from vtkmodules.util.numpy_support import vtk_to_numpy

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
resmr = os.environ["RESMR_EXECUTABLE"]
os.makedirs(args.temp, exist_ok=True)
egrid = os.path.join(args.data, "spe9/opmflow2022_run_of_opm-data_SPE9_CP/SPE9_CP.EGRID")
path = os.path.join(args.temp, "spe9.resmr")
if os.path.exists(path[:-6] + ".resmrp"):
    os.remove(path[:-6] + ".resmrp")  # an earlier run's, for the geometry built before
subprocess.run([resmr, "build", egrid, "-o", path, "--quiet"], capture_output=True, text=True, check=True)
subprocess.run([resmr, "add-properties", path, egrid], capture_output=True, text=True, check=True)

reader = simple.OpenDataFile(path)
if reader.GetXMLName() != "MultiresolutionReader":
    rt.fail(f"File > Open on .resmr picked {reader.GetXMLName()}, not MultiresolutionReader")
reader.UpdatePipeline()
descriptor = servermanager.Fetch(reader)
if descriptor.GetNumberOfPoints() != 8 or descriptor.GetNumberOfCells() != 12:
    rt.fail(f"descriptor has {descriptor.GetNumberOfPoints()} points, {descriptor.GetNumberOfCells()} cells; 8 and 12 expected")

full = simple.OpenDataFile(egrid)
if full.GetXMLName() != "EGRIDReader":
    rt.fail(f"the EGRID opened with {full.GetXMLName()}")
full.UpdatePipeline()
expected = full.GetDataInformation().GetBounds()
got = descriptor.GetBounds()
tolerance = 1e-3 * max(expected[1] - expected[0], expected[3] - expected[2])
if any(abs(a - b) > tolerance for a, b in zip(got, expected)):
    rt.fail(f"descriptor bounds {got} differ from the EGRID's {expected}")
print(f"bounds {got}")

steps = list(reader.TimestepValues)
full_steps = list(full.TimestepValues)
if len(steps) < 2 or len(steps) != len(full_steps) or any(abs(a - b) > 1e-6 for a, b in zip(steps, full_steps)):
    rt.fail(f"time steps {steps[:5]}... differ from the EGRID reader's {full_steps[:5]}...")
print(f"{len(steps)} time steps, {steps[0]} to {steps[-1]} days")

names = [descriptor.GetCellData().GetArrayName(i) for i in range(descriptor.GetCellData().GetNumberOfArrays())]
for name in ("PORO", "PRESSURE", "SWAT"):
    if name not in names:
        rt.fail(f"property {name} not listed; arrays: {names}")


def simulator_range(name, time):
    full.UpdatePipeline(time)
    grid = servermanager.Fetch(full)
    values = vtk_to_numpy(grid.GetCellData().GetArray(name))
    values = values[np.isfinite(values)]
    return float(values.min()), float(values.max())


for time in (steps[1], steps[len(steps) // 2], steps[-1]):
    reader.UpdatePipeline(time)
    descriptor = servermanager.Fetch(reader)
    for name in ("PORO", "PRESSURE", "SWAT"):
        values = vtk_to_numpy(descriptor.GetCellData().GetArray(name))
        low, high = simulator_range(name, time)
        if not (math.isclose(values.min(), low, rel_tol=1e-6, abs_tol=1e-9) and
                math.isclose(values.max(), high, rel_tol=1e-6, abs_tol=1e-9)):
            rt.fail(f"{name} at {time} days: descriptor range [{values.min()}, {values.max()}], simulator [{low}, {high}]")
print("property ranges equal the simulator's at three steps")

# Damaged input: a truncated .resmr; a property file of another geometry beside it.
truncated = os.path.join(args.temp, "truncated.resmr")
with open(path, "rb") as source, open(truncated, "wb") as target:
    target.write(source.read()[: os.path.getsize(path) // 2])
rt.expect_read_error(simple.MultiresolutionReservoir(FileName=truncated), "truncated .resmr", [truncated])
other = os.path.join(args.temp, "other.resmr")
subprocess.run([resmr, "build", "synth:30x20x5", "-o", other, "--quiet"], capture_output=True, text=True, check=True)
shutil.copyfile(path[:-6] + ".resmrp", other[:-6] + ".resmrp")
rt.expect_read_error(simple.MultiresolutionReservoir(FileName=other), "foreign property file",
                     [other[:-6] + ".resmrp", "another geometry"])
print("MultiresolutionReader checks passed")
