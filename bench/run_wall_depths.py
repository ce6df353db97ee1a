"""What the wall depth table buys and costs, side by side in one run.

The generated 400x400x100 model (16M cells, 100 layers; built once into --scratch with
`resmr build` and `resmr add-properties`) and a copy whose wall depth table is damaged (one
byte: the viewer warns and paints walls from their coordinates, as files without the table):
for two whole-model views and three tolerances, each frame with every mesh loaded,
- quality: the share of pixels within 2 px of the exact frame (0 px, the same file) in the Cell
  Id colouring, and the share of what is missed that lies on cells below the first layer;
- cost: a still 1280x720 frame coloured by PORO, lit, grid lines on (the default look), p50 of
  ROUNDS x 10 renders, the two files taking turns round by round.

  pvpython bench/run_wall_depths.py --plugin PLUGIN.so --resmr build/bin/resmr --scratch DIR
Results: bench/results/wall_depths.{md,json}."""
import argparse
import json
import os
import platform
import shutil
import subprocess
import sys
import time

import numpy as np
from paraview import simple

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "Testing", "Python"))
import image_metrics  # noqa: E402
import resmr_testing  # noqa: E402

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", required=True)
parser.add_argument("--resmr", required=True)
parser.add_argument("--scratch", required=True)
parser.add_argument("--tolerances", type=float, nargs="+", default=[8, 16, 48])
parser.add_argument("--rounds", type=int, default=3)
parser.add_argument("--out", default=os.path.join(HERE, "results", "wall_depths"))
args = parser.parse_args()
WIDTH, HEIGHT = 1280, 720
NX, NY, NZ = 400, 400, 100
SPEC = f"synth:{NX}x{NY}x{NZ}:1"

os.makedirs(args.scratch, exist_ok=True)
path = os.path.join(args.scratch, f"walls_{NX}x{NY}x{NZ}.resmr")
if not os.path.exists(path + "p"):
    subprocess.run([args.resmr, "build", SPEC, "-o", path, "--quiet"], check=True, stdout=subprocess.DEVNULL)
    subprocess.run([args.resmr, "add-properties", path, SPEC], check=True, stdout=subprocess.DEVNULL)

damaged = os.path.join(args.scratch, f"walls_{NX}x{NY}x{NZ}-damaged.resmr")
if not resmr_testing.damage_wall_table(path, damaged):
    sys.exit(f"{path}: not exactly one wall depth chunk")
shutil.copyfile(path + "p", damaged + "p")  # the geometry id is the chunks' recorded checksums

simple.LoadPlugin(args.plugin, remote=False, ns=globals())
view = resmr_testing.image_view(WIDTH, HEIGHT)
FILES = {"with the table": path, "table damaged": damaged}
displays = {}
for name, file in FILES.items():
    reader = simple.OpenDataFile(file)
    display = simple.Show(reader, view)
    display.MemoryBudgetMB = 8192
    display.WaitForDetailMs = 600000
    display.TargetFrameRate = 0
    displays[name] = (reader, display)
    simple.Hide(reader, view)
bounds = displays["with the table"][0].GetDataInformation().GetBounds()
cx, cy, cz = (bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2, (bounds[4] + bounds[5]) / 2
size = max(bounds[1] - bounds[0], bounds[3] - bounds[2])
CAMERAS = {"overview": (cx + 1.2 * size, cy, cz + 0.6 * size),
           "overview, a quarter turn": (cx, cy + 1.2 * size, cz + 0.6 * size)}


def show(name, camera, tolerance, paint):
    for other, (reader, _) in displays.items():
        (simple.Show if other == name else simple.Hide)(reader, view)
    display = displays[name][1]
    display.PaintBy = paint
    display.GridLines = 1 if paint == "Property" else 0
    if paint == "Property":
        simple.ColorBy(display, ("CELLS", "PORO"))
    display.PixelTolerance = tolerance
    view.GetActiveCamera().SetPosition(CAMERAS[camera])
    view.GetActiveCamera().SetFocalPoint(cx, cy, cz)
    view.GetActiveCamera().SetViewUp(0, 0, 1)


def ids(name, camera, tolerance):
    show(name, camera, tolerance, "Cell Id")
    return resmr_testing.cell_ids(resmr_testing.capture_rgb(view, os.path.join(args.scratch, "frame.png"),
                                                            WIDTH, HEIGHT))


rows = []
for camera in CAMERAS:
    exact = ids("with the table", camera, 0)
    for tolerance in args.tolerances:
        row = {"camera": camera, "tolerance": tolerance}
        for name in FILES:
            got = ids(name, camera, tolerance)
            missed = image_metrics.missed_pixels(got, exact)
            row[name] = {"within_2px": image_metrics.compare(got, exact)["within_2px"],
                         "missed_on_walls": float((missed & (exact > NX * NY)).sum() / max(missed.sum(), 1)),
                         "ms": []}
        for _ in range(args.rounds):
            for name in FILES:
                show(name, camera, tolerance, "Property")
                simple.Render(view)  # loads what this tolerance wants; not timed
                for _ in range(10):
                    start = time.perf_counter()
                    simple.Render(view)
                    row[name]["ms"].append(1000 * (time.perf_counter() - start))
        for name in FILES:
            row[name]["p50_ms"] = float(np.median(row[name]["ms"]))
        rows.append(row)
        print(f"{camera} {tolerance:g} px: " + "; ".join(
            f"{name}: {100 * row[name]['within_2px']:.1f}% within 2 px, {row[name]['p50_ms']:.1f} ms"
            for name in FILES), flush=True)

machine = f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores"
with open(args.out + ".json", "w") as out:
    json.dump({"machine": machine, "date": time.strftime("%Y-%m-%d"), "rows": rows}, out, indent=1)
lines = [f"# The wall depth table, side by side (generated faulted model {NX}x{NY}x{NZ}, {WIDTH}x{HEIGHT}, llvmpipe)",
         "", f"Machine: {machine}, Mesa llvmpipe; {time.strftime('%Y-%m-%d')}. 'Table damaged': the same file with one "
         "byte of its wall depth table changed, so the viewer paints walls from their coordinates as files without "
         "the table. 'Within 2 px': pixels whose cell (or the background) the exact frame (0 px, Cell Id colouring) "
         "has within 2 pixels, every mesh loaded; 'missed on walls': the share of the missed pixels whose exact cell "
         f"lies below the first layer. Frame: a still frame coloured by PORO, lit, grid lines on, p50 of "
         f"{args.rounds} x 10 renders, the two files taking turns.", "",
         "| camera | tolerance px | within 2 px: table / damaged | missed on walls: table / damaged | "
         "frame ms p50: table / damaged |", "|---|---|---|---|---|"]
for row in rows:
    t, d = row["with the table"], row["table damaged"]
    lines.append(f"| {row['camera']} | {row['tolerance']:g} | {100 * t['within_2px']:.1f}% / "
                 f"{100 * d['within_2px']:.1f}% | {100 * t['missed_on_walls']:.0f}% / "
                 f"{100 * d['missed_on_walls']:.0f}% | {t['p50_ms']:.1f} / {d['p50_ms']:.1f} |")
with open(args.out + ".md", "w") as out:
    out.write("\n".join(lines) + "\n")
print("wrote", args.out + ".md")
