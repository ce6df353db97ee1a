"""A simulator run still being written, on copies of real runs made here (never committed).

EGRIDReader: EIGHTCELLS' UNRST is appended a piece at a time (inside a record, then through
each step's ENDSOL) while a reader holds the run open; after each piece, ReloadFiles (what
File > Reload Files calls) offers exactly the complete steps: the reader's and the time
keeper's time steps grow by one when a step closes, each new step's PRESSURE and SWAT equal a
reader's on the whole run, and the Warnings name the step left out and its byte offset while
a step is cut.

Multiresolution Reservoir: Reek's UNRST grows in three stages (cut inside step 3, inside
step 4, whole); resmr add-properties after each adds the new steps to the .resmrp; after
ReloadFiles the reader offers them, and the Multiresolution Surface coloured by PRESSURE at
the new step draws what a freshly opened view of the final files draws (and not the step
before's picture)."""
import json
import os
import shutil
import struct
import subprocess

import numpy as np
from paraview import servermanager, simple
from vtkmodules.util.numpy_support import vtk_to_numpy

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
work = os.path.join(args.temp, "run-being-written")
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
WIDTH, HEIGHT = 480, 360


def records(data):
    """(name, header offset, end offset) of each record of an unformatted keyword file in the
    standard layout (1000 numbers or 105 strings a block)."""
    position = 0
    while position < len(data):
        _, name, count, kind, _ = struct.unpack(">i8si4si", data[position:position + 24])
        kind = kind.decode()
        size = {"INTE": 4, "REAL": 4, "LOGI": 4, "DOUB": 8, "CHAR": 8, "MESS": 0}.get(kind)
        if size is None:
            size = int(kind[1:])
        per_block = 105 if kind.startswith("C") else 1000
        blocks = (count + per_block - 1) // per_block if size else 0
        end = position + 24 + count * size + 8 * blocks
        yield name.decode().strip(), position, end
        position = end


def fetch(reader, time):
    reader.UpdatePipeline(time)
    return servermanager.Fetch(reader, arg1=None, arg2=None, idx=0)


def values(grid, name):
    array = grid.GetCellData().GetArray(name)
    if array is None:
        rt.fail(f"{name} missing")
    return vtk_to_numpy(array)


# ------------------------------------------------------------------ EGRIDReader
source = os.path.join(args.data, "format_variants/res2df_eightcells/EIGHTCELLS")
folder = os.path.join(work, "eightcells")
os.makedirs(folder)
for extension in (".EGRID", ".INIT"):
    shutil.copy(source + extension, os.path.join(folder, "RUN" + extension))
with open(source + ".UNRST", "rb") as handle:
    unrst = handle.read()
# Not registered, so that the time keeper holds the run's steps only.
whole = servermanager.sources.EGRIDReader(FileName=source + ".EGRID")
whole.UpdatePipelineInformation()
whole_times = list(whole.TimestepValues)
if len(whole_times) != 3:
    rt.fail(f"EIGHTCELLS: {len(whole_times)} steps, expected 3")

# The pieces a writer appends: up to the middle of the first PRESSURE, then in each step to
# the middle of its SWAT, to its ENDSOL, and the first 30 bytes of the next step.
ends = []
for name, start, end in records(unrst):
    if name in ("PRESSURE", "SWAT"):
        ends.append(((start + end) // 2, False))
    if name == "ENDSOL":
        ends.append((end, True))
        if end < len(unrst):
            ends.append((end + 30, False))
run_path = os.path.join(folder, "RUN.UNRST")
with open(run_path, "wb") as handle:
    handle.write(unrst[:ends[0][0]])
reader = simple.EGRIDReader(FileName=os.path.join(folder, "RUN.EGRID"))
reader.UpdatePipeline()
reader.UpdatePropertyInformation()
if list(reader.TimestepValues):
    rt.fail(f"first step cut: {len(reader.TimestepValues)} steps offered")
if "left out" not in reader.GetPropertyValue("Warnings"):
    rt.fail(f"first step cut: no warning: {reader.GetPropertyValue('Warnings')!r}")
if reader.GetPropertyValue("LastError"):
    rt.fail(f"first step cut: {reader.GetPropertyValue('LastError')}")
keeper = simple.GetTimeKeeper()

written = ends[0][0]
complete = 0
for end, closes in ends[1:]:
    with open(run_path, "ab") as handle:  # appended, as the simulator writes
        handle.write(unrst[written:end])
    written = end
    complete += closes
    before = len(reader.TimestepValues)
    if not simple.ReloadFiles(reader):
        rt.fail("ReloadFiles: the EGRID reader does not support reloading")
    reader.UpdatePropertyInformation()
    times = list(reader.TimestepValues)
    warnings = reader.GetPropertyValue("Warnings")
    cut = end < len(unrst) and not closes
    print(f"UNRST of {end} bytes: {len(times)} steps offered (complete {complete}); "
          f"time keeper {len(keeper.TimestepValues)} steps; warned: {'left out' in warnings}")
    if len(times) != complete or times != whole_times[:complete]:
        rt.fail(f"UNRST of {end} bytes: steps {times}, expected {whole_times[:complete]}")
    if len(keeper.TimestepValues) != complete:
        rt.fail(f"UNRST of {end} bytes: the time keeper has {len(keeper.TimestepValues)} steps")
    if cut != ("left out: incomplete at byte" in warnings):
        rt.fail(f"UNRST of {end} bytes: warnings {warnings!r}")
    if cut and "RUN.UNRST" not in warnings:
        rt.fail(f"UNRST of {end} bytes: the warning does not name the file: {warnings!r}")
    if len(times) > before:
        time = times[-1]
        got, expected = fetch(reader, time), fetch(whole, time)
        for name in ("PRESSURE", "SWAT"):
            if not np.array_equal(values(got, name), values(expected, name), equal_nan=True):
                rt.fail(f"step at {time} days: {name} differs from the whole run's")
        if reader.GetPropertyValue("LastError"):
            rt.fail(f"step at {time} days: {reader.GetPropertyValue('LastError')}")
if complete != 3:
    rt.fail(f"{complete} steps closed, expected 3")
simple.Delete(reader)
del whole
print("EGRIDReader: every reload offered exactly the complete steps, with the whole run's values")

# ------------------------------------------------------------------ Multiresolution Reservoir
resmr = os.environ["RESMR_EXECUTABLE"]
source = os.path.join(args.data, "reek/res2df_sim/eclipse/model/2_R001_REEK-0")
folder = os.path.join(work, "reek")
os.makedirs(folder)
for extension in (".EGRID", ".INIT"):
    os.symlink(source + extension, os.path.join(folder, "RUN" + extension))
with open(source + ".UNRST", "rb") as handle:
    unrst = handle.read()
starts = [start for name, start, _ in records(unrst) if name == "SEQNUM"]
geometry = os.path.join(folder, "run.resmr")
subprocess.run([resmr, "build", os.path.join(folder, "RUN.EGRID"), "-o", geometry, "--quiet"], check=True)


def add_properties(size):
    with open(os.path.join(folder, "RUN.UNRST"), "wb") as handle:
        handle.write(unrst[:size])
    done = subprocess.run([resmr, "add-properties", geometry, os.path.join(folder, "RUN.EGRID")],
                          capture_output=True, text=True)
    if done.returncode != 0:
        rt.fail(f"add-properties on {size} bytes: exit {done.returncode}: {done.stderr}")
    return json.loads(done.stdout)


view = rt.image_view(WIDTH, HEIGHT)
lut = simple.GetColorTransferFunction("PRESSURE")


def show(reader):
    display = simple.Show(reader, view)
    display.PaintBy = "Property"
    display.PixelTolerance = 0
    display.GridLines = 0
    display.WaitForDetailMs = 120000
    rt.unlit(display)
    simple.ColorBy(display, ("CELLS", "PRESSURE"))
    return display


def picture(reader, time, name):
    view.ViewTime = time
    reader.UpdatePipeline(time)
    simple.Render(view)
    return rt.capture_rgb(view, os.path.join(work, name + ".png"), WIDTH, HEIGHT)


report = add_properties(starts[2] + 1000)  # step 3 cut
print(f"add-properties, step 3 cut: {report}")
reader = simple.OpenDataFile(geometry)
reader.UpdatePipelineInformation()
if len(reader.TimestepValues) != 2:
    rt.fail(f".resmrp of 2 complete steps: {len(reader.TimestepValues)} steps offered")
show(reader)
view.ResetCamera(False)
lut.AutomaticRescaleRangeMode = "Never"
picture(reader, reader.TimestepValues[-1], "reek-step2")
rt.place_camera(view, reader.GetDataInformation().GetBounds(), 1.0, [0.3, -0.5, 0.8], 1.0)
for size, steps in ((starts[3] + 5, 3), (len(unrst), 4)):
    report = add_properties(size)
    print(f"add-properties on {size} bytes: {report}")
    if report["tables_kept"] <= 0 or report["left_out"] != (1 if size < len(unrst) else 0):
        rt.fail(f"add-properties on {size} bytes: {report}")
    if len(reader.TimestepValues) != steps - 1:
        rt.fail("the reader offered new steps before Reload Files")
    simple.ReloadFiles(reader)
    if len(reader.TimestepValues) != steps:
        rt.fail(f"after reload: {len(reader.TimestepValues)} steps, expected {steps}")
times = list(reader.TimestepValues)
# One colour scale for every picture: the last two steps' pressure range.
reader.UpdatePipeline(times[-1])
data = servermanager.Fetch(reader)
pressure = vtk_to_numpy(data.GetCellData().GetArray("PRESSURE"))
reader.UpdatePipeline(times[-2])
earlier = vtk_to_numpy(servermanager.Fetch(reader).GetCellData().GetArray("PRESSURE"))
low, high = float(min(pressure[0], earlier[0])), float(max(pressure[1], earlier[1]))
lut.RescaleTransferFunction(low, high)
print(f"PRESSURE at {times[-1]} days: [{pressure[0]}, {pressure[1]}]; at {times[-2]}: [{earlier[0]}, {earlier[1]}]")
reloaded = picture(reader, times[-1], "reek-reloaded-last")
simple.Hide(reader, view)
fresh_reader = simple.OpenDataFile(geometry)
fresh_reader.UpdatePipelineInformation()
show(fresh_reader)
lut.RescaleTransferFunction(low, high)
fresh = picture(fresh_reader, times[-1], "reek-fresh-last")
fresh_before = picture(fresh_reader, times[-2], "reek-fresh-before-last")
covered = (fresh.sum(axis=2) > 0)
same = float(np.mean(np.max(np.abs(reloaded - fresh), axis=2)[covered] <= 3))
moved = float(np.mean(np.max(np.abs(fresh_before - fresh), axis=2)[covered] > 3))
print(f"Multiresolution Surface at the new step: {100 * same:.2f}% of {int(covered.sum())} pixels as a fresh view; "
      f"{100 * moved:.2f}% differ from the step before")
if covered.sum() < 1000:
    rt.fail("the Multiresolution Surface drew almost nothing")
if same < 0.99:
    rt.fail(f"after reload the surface draws {100 * same:.2f}% of the pixels as a fresh view (< 99%)")
if moved < 0.01:
    rt.fail("the last two steps look alike: the comparison shows nothing")
print("a run still being written: reloads offer the complete steps, the surface shows them")
