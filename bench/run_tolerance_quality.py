"""Picture quality against tolerance (the evidence behind MaximumPixelTolerance's default), run
with pvpython:

  pvpython bench/run_tolerance_quality.py --plugin PLUGIN.so --resmr build/bin/resmr \
      --scratch bench/scratch/quality [--model 400x300x25] [--tolerances 1 4 16 64 256 65536]

Builds the generated faulted model (the demo's, 3M cells; --model NIxNJxNK for another size)
and draws it at 1280x720 from four cameras (an overview from two sides, a close look, a low
flight along a fault) at each tolerance, waiting for every mesh, in the Cell Id colouring,
against the exact frame (0 px): the share of pixels within 2 px of the exact image, cell
agreement, see-through holes, silhouette distance, the triangles drawn, the share within 2 px
of the exact frame drawn at 3x
(Testing/Python/image_metrics.py), and below 2^24 cells where the missed pixels are (first
layer or below). Results: bench/results/tolerance_quality.{md,json}; the 400x400x100 model's
(100 layers): bench/results/tolerance_quality_400x400x100.{md,json}."""
import argparse
import json
import os
import subprocess
import sys

from paraview import simple

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "Testing", "Python"))
import image_metrics  # noqa: E402
import resmr_testing  # noqa: E402

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", required=True)
parser.add_argument("--resmr", required=True)
parser.add_argument("--scratch", required=True)
parser.add_argument("--model", default="400x300x25")
parser.add_argument("--tolerances", type=float, nargs="+", default=[1, 4, 16, 32, 64, 128, 256, 65536])
parser.add_argument("--simplify-faults", action="store_true",
                    help="build with resmr build --simplify-faults (each fault block's outline simplified on its own)")
parser.add_argument("--out", default=os.path.join(HERE, "results", "tolerance_quality"))
args = parser.parse_args()
WIDTH, HEIGHT = 1280, 720

os.makedirs(args.scratch, exist_ok=True)
dims = args.model.split("x")
grid = os.path.join(args.scratch, f"faulted_{args.model}.EGRID")
path = os.path.join(args.scratch, f"faulted_{args.model}{'-simplify-faults' if args.simplify_faults else ''}.resmr")
if not os.path.exists(path):
    if not os.path.exists(grid):
        subprocess.run([args.resmr, "synth", *dims, "-o", grid, "--quiet"], check=True, stdout=subprocess.DEVNULL)
    subprocess.run([args.resmr, "build", grid, "-o", path, "--quiet", *(["--simplify-faults"] if args.simplify_faults else [])],
                   check=True, stdout=subprocess.DEVNULL)

simple.LoadPlugin(args.plugin, remote=False, ns=globals())
view = resmr_testing.image_view(WIDTH, HEIGHT)
reader = simple.OpenDataFile(path)
display = simple.Show(reader, view)
display.GridLines = 0
display.PaintBy = "Cell Id"
display.MemoryBudgetMB = 8192
display.WaitForDetailMs = 600000
simple.Render(view)
b = reader.GetDataInformation().GetBounds()
cx, cy, cz = (b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2
size = max(b[1] - b[0], b[3] - b[2])
cameras = {"overview": ((cx + 1.2 * size, cy, cz + 0.6 * size), (cx, cy, cz)),
           "overview, a quarter turn": ((cx, cy + 1.2 * size, cz + 0.6 * size), (cx, cy, cz)),
           "close look": ((cx + 0.3 * size, cy - 0.2 * size, cz + 0.15 * size), (cx, cy, cz)),
           "low flight": ((b[0] + 0.3 * (b[1] - b[0]), cy - 0.05 * size, b[5] + 0.02 * size),
                          (b[0] + 0.4 * (b[1] - b[0]), cy, cz))}


FINE_SCALE = 3  # the exact frame also at 3x: every cell thinner than a pixel shows there


def draw(camera, tolerance, scale=1):
    position, focal = cameras[camera]
    view.GetActiveCamera().SetPosition(position)
    view.GetActiveCamera().SetFocalPoint(focal)
    view.GetActiveCamera().SetViewUp(0, 0, 1)
    display.PixelTolerance = tolerance
    ids = resmr_testing.cell_ids(resmr_testing.capture_rgb(view, os.path.join(args.scratch, "frame.png"),
                                                           scale * WIDTH, scale * HEIGHT))
    display.UpdatePropertyInformation()
    return ids, int(display.GetPropertyValue("TrianglesDrawn")), display.GetPropertyValue("CurrentEstimatedError")


# Cell ids are 24-bit: below 2^24 cells the layer of each pixel's cell is known, and the pixels
# a frame misses can be told apart: on first-layer cells (the top, mostly) or below (walls).
nx, ny, nz = (int(v) for v in dims)
layers_known = nx * ny * nz < 2 ** 24
rows = []
for camera in cameras:
    fine = draw(camera, 0, FINE_SCALE)[0]
    exact, exact_triangles, _ = draw(camera, 0)
    for tolerance in args.tolerances:
        got, triangles, estimated = draw(camera, tolerance)
        row = {"camera": camera, "tolerance": tolerance, "estimated_px": estimated, "triangles": triangles,
               "exact_triangles": exact_triangles}
        row.update(image_metrics.compare(got, exact))
        row["within_2px_fine"] = image_metrics.within_pixels(got, fine, scale=FINE_SCALE)
        if layers_known:
            missed = image_metrics.missed_pixels(got, exact)
            row["missed_below_first_layer"] = int((missed & (exact > nx * ny)).sum())
            row["missed"] = int(missed.sum())
        rows.append(row)
        print(f"{camera} {tolerance:g} px (estimated {estimated:.2f} px): {100 * row['within_2px']:.1f}% within 2 px "
              f"({100 * row['within_2px_fine']:.1f}% of the {FINE_SCALE}x exact frame), {100 * row['cell_agreement']:.1f}% "
              f"same cell, {row['hole_pixels']} hole px, silhouette {row['silhouette_px']} px, {triangles} triangles",
              flush=True)

with open(args.out + ".json", "w") as out:
    json.dump({"model": f"faulted {args.model}", "size": [WIDTH, HEIGHT], "rows": rows}, out, indent=1)
built = "built with --simplify-faults" if args.simplify_faults else "default build"
lines = [f"# Picture quality against tolerance (generated faulted model {args.model}, {built}, {WIDTH}x{HEIGHT}, "
         "llvmpipe)", "",
         "Each frame waits for every mesh its tolerance selects and is compared with the exact frame (0 px) of "
         "the same camera in the Cell Id colouring: 'within 2 px' is the share of pixels whose cell (or the "
         "background) the exact frame has within 2 pixels; 'missed below layer 1' is the share of the other "
         "pixels whose exact cell lies below the first layer (walls: the outside and the faults, where every "
         "layer shows). 'of the 3x frame': the same against the exact frame drawn at 3x the resolution, where "
         "cells thinner than a pixel all show (image_metrics.within_pixels(scale=3); the 1x exact frame is its centre "
         "samples and scores 100% by it). 'estimated px' is the frame's estimated error (the typical errors of the drawn regions "
         "seen at their centres, averaged over the view by the share each covers; CurrentEstimatedError), what "
         "the frame rate steers by beside the tolerance, a bound.", "",
         "| camera | tolerance px | estimated px | within 2 px | of the 3x frame | missed below layer 1 | same cell | hole px | silhouette px | "
         "triangles (0 px: all) |",
         "|---|---|---|---|---|---|---|---|---|---|"]
for row in rows:
    below = (f"{100 * row['missed_below_first_layer'] / row['missed']:.0f}%" if row.get("missed") else "-")
    lines.append(f"| {row['camera']} | {row['tolerance']:g} | {row['estimated_px']:.2f} | {100 * row['within_2px']:.1f}% | "
                 f"{100 * row['within_2px_fine']:.1f}% | {below} | "
                 f"{100 * row['cell_agreement']:.1f}% | {row['hole_pixels']} | {row['silhouette_px']} | "
                 f"{row['triangles']:,} ({row['exact_triangles']:,}) |")
with open(args.out + ".md", "w") as out:
    out.write("\n".join(lines) + "\n")
