"""Walls show their layers where they are, at every level.

On a faulted synthetic model of 48 layers (built with `resmr build`), shown with its depth
exaggerated 6 times (layers a few pixels thick), seen from two sides where the outside and
the faults show every layer, drawn at tolerances from 4 px to the roots
in the Cell Id colouring: where a frame and the exact frame (0 px, the same camera) name the
same column below the top layer, the layers they name differ by at most one on >= MIN_SHARE of
those pixels in every frame (a coarse wall's own interpolated coordinates put them many
layers off).

The same frames from a copy of the file whose wall depth table is damaged (one byte changed;
the viewer warns and paints the walls from their coordinates, as before the table) must do
worse: at most MAX_SHARE_WITHOUT in the worst frame, so this test fails if the table stops
being used."""
import os

import numpy as np
from paraview import simple

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
temp = os.path.join(args.temp, "wall-layers")
os.makedirs(temp, exist_ok=True)
WIDTH, HEIGHT = 640, 480
NX, NY, NZ = 80, 60, 48
EXAGGERATION = 6
MIN_SHARE = 0.92
MAX_SHARE_WITHOUT = 0.85
TOLERANCES = [4, 16, 64, 256, 65536]
CAMERAS = [("south-east", [1.0, -0.6, 0.3], 1.4), ("north-west", [-0.7, 1.0, 0.35], 1.4)]

grid = os.path.join(temp, "walls.EGRID")
path = os.path.join(temp, "walls.resmr")
rt.run_resmr("synth", str(NX), str(NY), str(NZ), "-o", grid, "--faults", "6", "--throw", "0.4", "--quiet")
rt.run_resmr("build", grid, "-o", path, "--quiet")

# The copy with a damaged wall depth table.
damaged = os.path.join(temp, "walls-damaged.resmr")
if not rt.damage_wall_table(path, damaged):
    rt.fail(f"{path}: not exactly one wall depth chunk")

view = rt.image_view(WIDTH, HEIGHT)


def shares(file):
    """Per frame: the share of same-column pixels below the top layer whose layers differ by at
    most one from the exact frame's."""
    reader = simple.OpenDataFile(file)
    display = simple.Show(reader, view)
    display.Scale = [1, 1, EXAGGERATION]
    display.GridLines = 0
    display.PaintBy = "Cell Id"
    display.WaitForDetailMs = 120000
    simple.Render(view)
    bounds = reader.GetDataInformation().GetBounds()
    result = {}
    for camera, direction, zoom in CAMERAS:
        rt.place_camera(view, bounds, EXAGGERATION, direction, zoom)
        display.PixelTolerance = 0
        exact = rt.cell_ids(rt.capture_rgb(view, os.path.join(temp, f"{camera}-exact.png"), WIDTH, HEIGHT))
        for tolerance in TOLERANCES:
            display.PixelTolerance = tolerance
            got = rt.cell_ids(rt.capture_rgb(view, os.path.join(temp, f"{camera}-{tolerance}.png"), WIDTH, HEIGHT))
            e, g = exact.astype(np.int64) - 1, got.astype(np.int64) - 1
            wall = (e >= NX * NY) & (g >= 0) & (e % (NX * NY) == g % (NX * NY))
            close = np.abs(e // (NX * NY) - g // (NX * NY)) <= 1
            result[(camera, tolerance)] = (float(np.mean(close[wall])) if wall.any() else 1.0, int(wall.sum()))
    simple.Delete(reader)
    return result


with_table = shares(path)
without = shares(damaged)
failures = []
for key, (share, pixels) in with_table.items():
    print(f"{key[0]} {key[1]} px: {100 * share:.2f}% of {pixels} wall pixels within a layer "
          f"({100 * without[key][0]:.2f}% without the table)")
    if share < MIN_SHARE:
        failures.append(f"{key[0]} {key[1]} px: {100 * share:.2f}% of {pixels} wall pixels within a layer")
    if pixels < 2000:
        failures.append(f"{key[0]} {key[1]} px: only {pixels} wall pixels compared")
worst_without = min(share for share, _ in without.values())
if worst_without > MAX_SHARE_WITHOUT:
    failures.append(f"without the table the worst frame still has {100 * worst_without:.2f}% within a layer: "
                    f"the check cannot tell")
if failures:
    rt.fail("; ".join(failures))
print("PASS")
