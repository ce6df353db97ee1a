"""Every level of the hierarchy watertight and painted honestly.

On the faulted synthetic model, Reek and Brugge (each built with `resmr build` by default, with
`--fault-columns 1` and with `--simplify-faults`, and `resmr add-properties`), drawn at tolerances from 1 px to 65536 px
(every level from the leaves to the roots: each doubling) from 4 cameras, and at 8 random
tolerances from random cameras (random conformal cuts, seeded):
- no see-through hole in a default build (background pixels that no background of the exact
  frame, 0 px, the same camera, Cell Id colouring, reaches: image_metrics.see_through_holes):
  the faults' columns are kept at every level of these models, and where a region border
  follows a fault its two sides are locked as any border is; nor with `--fault-columns 1`, where
  no fault fits and the two sides of every fault weld into one surface above the leaves, as
  at the coarsest levels of a large model. With `--simplify-faults` (each
  fault block's outline simplified on its own) the holes are counted and printed, not
  asserted: 45 to 68 of the 76 frames of each model;
- no fragment names a cell without a value: coloured by PORO (a value in every active cell),
  unlit, with the lookup table's NaN colour set to pure magenta, no pixel in that colour;
- every fragment shows its own cell's value: where the Cell Id frame of the same cut names an
  active cell, the PORO frame's colour is the lookup table's colour of that cell's PORO (as
  EGRIDReader reads it) within 3 levels a channel on >= 99.9% of those pixels.
Images of failures are left in the temporary folder."""
import math
import os
import random

import numpy as np
from paraview import simple

import image_metrics as im
import resmr_testing as rt
from paraview import servermanager
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy

args = rt.arguments()
rt.load_plugin(args.plugin)
temp = os.path.join(args.temp, "every-level")
os.makedirs(temp, exist_ok=True)
WIDTH, HEIGHT = 480, 360
NAN = [1.0, 0.0, 1.0]

MODELS = [
    ("faulted", rt.faulted_synthetic(temp)),
    ("reek", os.path.join(args.data, "reek/res2df_sim/eclipse/model/2_R001_REEK-0.EGRID")),
    ("brugge", os.path.join(args.data, "brugge/Real0/BRUGGE_0000.EGRID")),
]
CAMERAS = [("above", [0.3, -0.5, 0.8], 1.0), ("side", [1.0, -0.3, 0.25], 1.3),
           ("below", [-0.4, 0.5, -0.7], 1.0), ("close", [0.5, 0.6, 0.4], 2.5)]

view = rt.image_view(WIDTH, HEIGHT)
failures = []
rng = random.Random(31)
BUILDS = [("", [], True), ("welded", ["--fault-columns", "1"], True), ("simplify-faults", ["--simplify-faults"], False)]
for (name, grid), (variant, options, watertight) in [(m, b) for m in MODELS for b in BUILDS]:
    label = name + (f" ({' '.join(options)})" if options else "")
    path = os.path.join(temp, name + ("-" + variant if variant else "") + ".resmr")
    if not os.path.exists(path):
        rt.run_resmr("build", grid, "-o", path, "--quiet", *options)
    if not os.path.exists(path + "p"):
        rt.run_resmr("add-properties", path, grid)
    # Each cell's PORO by natural index (NaN where inactive), from the grid reader.
    grid_data = servermanager.Fetch(simple.EGRIDReader(FileName=grid, ApplyMapAxes=0))
    cells = grid_data.GetCellData()
    index = [vtk_to_numpy(cells.GetArray(a)).astype(np.int64) - 1 for a in ("I", "J", "K")]
    dims = [int(i.max()) + 1 for i in index]
    poro = np.full(dims[0] * dims[1] * dims[2], np.nan)
    poro[index[0] + dims[0] * (index[1] + dims[1] * index[2])] = vtk_to_numpy(cells.GetArray("PORO"))
    reader = simple.OpenDataFile(path)
    reader.ApplyMapAxes = 0
    display = simple.Show(reader, view)
    display.GridLines = 0
    display.WaitForDetailMs = 120000
    rt.unlit(display)
    simple.ColorBy(display, ("CELLS", "PORO"))
    lut = simple.GetColorTransferFunction("PORO")
    lut.NanColor = NAN
    simple.Render(view)
    table = lut.GetClientSideObject()
    worst_share = 1.0
    bounds = reader.GetDataInformation().GetBounds()
    cuts = [(t, c) for t in [2.0 ** e for e in range(17)] for c in CAMERAS]
    for _ in range(8):
        direction = [rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)]
        cuts.append((2.0 ** rng.uniform(0, 12), ("random", direction, rng.uniform(0.8, 3.0))))
    worst_nan = frames_with_holes = 0
    exact = {}
    for tolerance, (camera, direction, zoom) in cuts:
        rt.place_camera(view, bounds, 1.0, direction, zoom)
        key = (camera, tuple(direction), zoom)
        if key not in exact:
            display.PaintBy = "Cell Id"
            display.PixelTolerance = 0
            exact[key] = rt.cell_ids(rt.capture_rgb(view, os.path.join(temp, "exact.png"), WIDTH, HEIGHT))
        display.PaintBy = "Cell Id"
        display.PixelTolerance = tolerance
        ids = rt.cell_ids(rt.capture_rgb(view, os.path.join(temp, "ids.png"), WIDTH, HEIGHT))
        holes, depth = im.see_through_holes(ids, exact[key])
        frames_with_holes += holes > 0
        if holes:
            print(f"  {label} {camera} {tolerance:g} px: {holes} see-through hole pixels, {depth} deep")
            if watertight:
                failures.append(f"{label} {camera} {tolerance:g} px: {holes} see-through hole pixels")
        display.PaintBy = "Property"
        tag = f"{name}{'-' + variant if variant else ''}-{camera}-{tolerance:g}px"
        pixels = rt.capture_rgb(view, os.path.join(temp, tag + ".png"), WIDTH, HEIGHT)
        nan = im.nan_pixels(pixels, NAN)
        worst_nan = max(worst_nan, nan)
        # Own values: the lookup table's colour of the named cell's PORO, active cells only.
        named = ids > 0
        values = np.where(named, poro[np.maximum(ids - 1, 0)], np.nan)
        checked = named & ~np.isnan(values)
        if checked.any():
            unique, inverse = np.unique(values[checked], return_inverse=True)
            mapped = table.MapScalars(numpy_to_vtk(unique.astype(np.float64), deep=1), 1, -1)  # map scalars
            colours = vtk_to_numpy(mapped)[:, :3].astype(np.int64)
            close = np.max(np.abs(pixels[checked] - colours[inverse]), axis=1) <= 3
            share = float(np.mean(close))
            worst_share = min(worst_share, share)
            if share < 0.999:
                failures.append(f"{tag}: {100 * share:.2f}% of {int(checked.sum())} pixels show their cell's PORO")
        if nan:
            failures.append(f"{tag}: {nan} pixels in the NaN colour")
        else:
            os.remove(os.path.join(temp, tag + ".png"))
    print(f"{label}: {len(cuts)} frames from 1 to 65536 px and random cuts: at most {worst_nan} NaN pixels; "
          f"{frames_with_holes} frames with see-through holes; at least {100 * worst_share:.2f}% of the pixels "
          f"naming an active cell show its PORO")
    if not exact or all(not (e > 0).any() for e in exact.values()):
        failures.append(f"{name}: nothing drawn")
    simple.Delete(reader)

if failures:
    rt.fail("; ".join(failures[:20]) + (f" (and {len(failures) - 20} more)" if len(failures) > 20 else ""))
print("PASS")
