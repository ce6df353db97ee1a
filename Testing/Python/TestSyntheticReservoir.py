"""Synthetic reservoirs end to end: `resmr synth` writes an EGRID + INIT + UNRST that the
project's EGRIDReader, OPM EclIO and (where installed) resdata open with the same dims and
active cells; the SyntheticReservoir source gives the very same grid and arrays in memory;
the readers and the source refuse what would not fit in memory with a message pointing to
the multiresolution path; bad command lines fail clearly and leave no file; the same seed
gives the same bytes; and images of a generated model match their baselines."""
import json
import os
import subprocess

import numpy as np
from paraview import servermanager, simple

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
RESMR = os.environ["RESMR_EXECUTABLE"]
TEMP = os.path.join(args.temp, "synthetic")
os.makedirs(TEMP, exist_ok=True)
for name in os.listdir(TEMP):
    os.remove(os.path.join(TEMP, name))


def synth(*arguments, expect_ok=True):
    run = subprocess.run([RESMR, "synth", *map(str, arguments), "--quiet"], capture_output=True, text=True)
    if expect_ok and run.returncode != 0:
        rt.fail(f"resmr synth {arguments}: exit {run.returncode}: {run.stderr}")
    return run


def fetch(proxy, time=None):
    if time is None:
        proxy.UpdatePipeline()
    else:
        proxy.UpdatePipeline(time)
    return servermanager.Fetch(proxy, arg1=None, arg2=None, idx=0)


def visible_cells(grid):
    ghosts = rt.cell_array(grid, "vtkGhostType")
    return int(np.count_nonzero((ghosts & 32) == 0))  # HIDDENCELL


# ---- resmr synth -> EGRID + INIT + UNRST, opened by three readers
egrid = os.path.join(TEMP, "SYN.EGRID")
summary = json.loads(synth(60, 50, 12, "--seed", 3, "--steps", 3, "-o", egrid).stdout)
if summary["files"] != [egrid, os.path.join(TEMP, "SYN.UNRST"), os.path.join(TEMP, "SYN.INIT")]:
    rt.fail(f"unexpected files {summary['files']}")
active = summary["active"]
print(f"resmr synth 60 50 12: {active} active of {summary['cells']} cells, "
      f"fault faces {summary['fault_face_fraction']:.3f}, {summary['seconds']:.3f} s")

reader = simple.OpenDataFile(egrid)
if reader is None or reader.GetXMLName() != "EGRIDReader":
    rt.fail("ParaView's reader factory did not choose EGRIDReader for a generated EGRID")
reader.UpdatePipelineInformation()
times = list(reader.TimestepValues)
if times != [1216.0, 2433.0, 3650.0]:
    rt.fail(f"time steps {times}, expected the report days 1216, 2433, 3650")
from_file = fetch(reader, times[-1])
if from_file.GetNumberOfCells() != 60 * 50 * 12 or visible_cells(from_file) != active:
    rt.fail(f"EGRIDReader: {from_file.GetNumberOfCells()} cells, {visible_cells(from_file)} shown, "
            f"expected 36000 and {active}")

from opm.io.ecl import EGrid  # noqa: E402  (Debian's python3-opm-common)
opm_grid = EGrid(egrid)
if list(opm_grid.dimension) != [60, 50, 12] or opm_grid.active_cells != active:
    rt.fail(f"OPM EclIO: dims {opm_grid.dimension}, active {opm_grid.active_cells}")
print(f"OPM EclIO: dims {list(opm_grid.dimension)}, active {opm_grid.active_cells}")

resdata_python = os.environ.get("RESMR_RESDATA_PYTHON", "")
if resdata_python:
    check = ("import sys, resdata.grid as g; x = g.Grid(sys.argv[1]); "
             "print(x.get_nx(), x.get_ny(), x.get_nz(), x.get_num_active())")
    run = subprocess.run([resdata_python, "-c", check, egrid], capture_output=True, text=True)
    if run.returncode != 0 or run.stdout.split() != ["60", "50", "12", str(active)]:
        rt.fail(f"resdata: {run.stdout!r} {run.stderr[-500:]!r}")
    print(f"resdata: dims and active {run.stdout.strip()}")
else:
    print("resdata: not checked (RESMR_RESDATA_PYTHON not set; see bench/results/synth_validity.md)")

# ---- the SyntheticReservoir source gives the same grid and arrays as the files
source = simple.SyntheticReservoir(Dimensions=[60, 50, 12], Seed=3, Steps=3)
source.UpdatePipelineInformation()
if list(source.TimestepValues) != times:
    rt.fail(f"SyntheticReservoir times {list(source.TimestepValues)} differ from the files' {times}")
in_memory = fetch(source, times[-1])
points_file, cells_file = rt.points_and_cells(from_file)
points_memory, cells_memory = rt.points_and_cells(in_memory)
if not (np.array_equal(points_file, points_memory) and np.array_equal(cells_file, cells_memory)):
    rt.fail("SyntheticReservoir's grid differs from the EGRID written by resmr synth")
for name in ("PORO", "PERMX", "PERMZ", "NTG", "PORV", "PRESSURE", "SWAT", "vtkGhostType"):
    a, b = rt.cell_array(from_file, name), rt.cell_array(in_memory, name)
    same = np.array_equal(a, b, equal_nan=True) if a.dtype.kind == "f" else np.array_equal(a, b)
    if not same:
        rt.fail(f"{name}: SyntheticReservoir and the written files differ")
print("SyntheticReservoir: grid, PORO, PERMX, PERMZ, NTG, PORV, PRESSURE, SWAT equal to the files")

# ---- too big for memory: refused, pointing to the multiresolution path
big = simple.EGRIDReader(FileName=egrid, MemoryLimitMB=1)
rt.expect_read_error(big, "EGRIDReader over its memory limit",
                     ["SYN.EGRID", "60 x 50 x 12", "in memory", "multiresolution", "resmr build"])
deck = os.path.join(TEMP, "SYN.GRDECL")
synth(60, 50, 12, "--seed", 3, "-o", deck)
big = simple.GRDECLReader(FileName=deck, MemoryLimitMB=1)
rt.expect_read_error(big, "GRDECLReader over its memory limit",
                     ["SYN.GRDECL", "60 x 50 x 12", "multiresolution", "resmr build"])
small = simple.GRDECLReader(FileName=deck)
if visible_cells(fetch(small)) != active:
    rt.fail("GRDECLReader on the generated deck: active cells differ from the EGRID's")
source.MemoryLimitMB = 1
source.UpdatePipeline(times[-1])
source.UpdatePropertyInformation()
text = source.GetPropertyValue("LastError")
if "resmr synth 60 50 12" not in text or "multiresolution" not in text:
    rt.fail(f"SyntheticReservoir over its memory limit: {text!r}")
print(f"SyntheticReservoir over its memory limit: {text}")
simple.Delete(source)

# ---- the same seed, the same bytes; another seed, another model
again = os.path.join(TEMP, "AGAIN.EGRID")
synth(60, 50, 12, "--seed", 3, "--steps", 3, "-o", again)
for extension in ("EGRID", "INIT", "UNRST"):
    with open(os.path.join(TEMP, "SYN." + extension), "rb") as a, open(os.path.join(TEMP, "AGAIN." + extension), "rb") as b:
        if a.read() != b.read():
            rt.fail(f"seed 3 gave different {extension} files")
other = os.path.join(TEMP, "OTHER.EGRID")
synth(60, 50, 12, "--seed", 4, "-o", other)
with open(egrid, "rb") as a, open(other, "rb") as b:
    if a.read() == b.read():
        rt.fail("seeds 3 and 4 gave the same EGRID")

# ---- bad command lines: a clear error, exit 1 or 2, no file under the final name
before = sorted(os.listdir(TEMP))
for arguments, fragments in [
        ((0, 50, 12, "-o", os.path.join(TEMP, "ZERO.EGRID")), ["at least 1", "0 x 50 x 12"]),
        ((60, 50, 99999999999999999999, "-o", os.path.join(TEMP, "HUGE.EGRID")), ["NZ is too large"]),
        ((5000000, 50, 12, "-o", os.path.join(TEMP, "WIDE.EGRID")), ["at most 1000000"]),
        ((1000, 1000, 300, "-o", os.path.join(TEMP, "BIG.EGRID")), ["268,435,455", "synth:1000x1000x300:1"]),
        ((60, 50, 12, "-o", "/nonexistent/folder/X.EGRID"), ["/nonexistent/folder/X.EGRID", "cannot create"]),
        ((60, 50, 12, "-o", os.path.join(TEMP, "X.VTU")), ["extension chooses the format"]),
        ((60, 50, 12, "--water", "2", "-o", os.path.join(TEMP, "W.EGRID")), ["water fraction"]),
        ((60, 50, 12, "--steps", "2", "-o", os.path.join(TEMP, "S.GRDECL")), ["report steps need EGRID"]),
        ((60, 50, 12, "--bogus", "-o", os.path.join(TEMP, "B.EGRID")), ["unknown option --bogus"])]:
    run = synth(*arguments, expect_ok=False)
    missing = [f for f in fragments if f not in run.stderr]
    if run.returncode not in (1, 2) or missing:
        rt.fail(f"resmr synth {arguments}: exit {run.returncode}, message lacks {missing}: {run.stderr!r}")
    print(f"resmr synth {' '.join(map(str, arguments[:3]))}...: {run.stderr.strip()[:150]}")
if sorted(os.listdir(TEMP)) != before:
    rt.fail(f"failed runs left files: {set(os.listdir(TEMP)) - set(before)}")

# ---- images of a generated model (also shown in the README next to a real one)
view = simple.CreateView("RenderView")
view.ViewSize = [800, 600]
view.OrientationAxesVisibility = 1
model = simple.SyntheticReservoir(Dimensions=[120, 100, 25], Seed=1, Steps=5)
model.UpdatePipelineInformation()
last = list(model.TimestepValues)[-1]
view.ViewTime = last
grid = fetch(model, last)
display = simple.Show(model, view)
display.SetRepresentationType("Surface With Edges")
display.EdgeColor = [0.15, 0.15, 0.15]
exaggeration = 8.0
display.Scale = [1.0, 1.0, exaggeration]
for array, preset, low, high, baseline in [("PORO", "Viridis (matplotlib)", 0.03, 0.3, "SyntheticReservoir_PORO.png"),
                                           ("SWAT", "Blue Orange (divergent)", 0.0, 1.0, "SyntheticReservoir_SWAT_last.png")]:
    simple.ColorBy(display, ("CELLS", array))
    lut = simple.GetColorTransferFunction(array)
    lut.ApplyPreset(preset, True)
    lut.RescaleTransferFunction(low, high)
    display.SetScalarBarVisibility(view, True)
    simple.Render(view)
    rt.place_camera(view, grid.GetBounds(), exaggeration, (-0.6, -1.0, 0.9), 1.3)
    rt.compare_image(view, args.baselines, baseline, args.temp)
    display.SetScalarBarVisibility(view, False)

# A cross-section (the cells of row J = 50) seen from the south: layers thinning and pinching
# out, fault offsets, sloping pillars and the flat oil-water contact under the active cells.
simple.Hide(model, view)
section = simple.Threshold(Input=model, Scalars=["CELLS", "J"], LowerThreshold=50, UpperThreshold=50)
section_display = simple.Show(section, view)
section_display.SetRepresentationType("Surface With Edges")
section_display.EdgeColor = [0.15, 0.15, 0.15]
section_display.Scale = [1.0, 1.0, 2 * exaggeration]
simple.ColorBy(section_display, ("CELLS", "PORO"))
section_display.SetScalarBarVisibility(view, True)
simple.Render(view)
rt.place_camera(view, grid.GetBounds(), 2 * exaggeration, (0.0, -1.0, 0.05), 1.45)
rt.compare_image(view, args.baselines, "SyntheticReservoir_section_J50.png", args.temp)
print("synthetic reservoir checks passed")
