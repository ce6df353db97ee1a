"""I/J/K range filter (Multiresolution Extract Subset) on large models, run with pvpython:

  pvpython bench/run_range_bench.py --plugin PLUGIN.so --models A.resmr B.resmr \
      [--peer-grid GRID.EGRID] [--out bench/results/range]

Each model (with its property file) is shown at 1280x720, coloured by PORO, lit, at the
default 1 px tolerance and a 1024 MB budget, from an oblique overview, through Multiresolution
Extract Subset. For each of a box, an I slice, a J slice and a K slab (VOI set from the
model's dimensions), the filter is changed and:
- first image: the wall time of the first render after the change, waiting for no detail
  (what a user sees first: the roots' masked meshes);
- full detail: renders back to back (none waiting for detail) until no load is pending, the
  wall time from the change to the first render with nothing pending;
- memory: the surface's resident MB (CPU buffers + GPU copies) against the budget, and the
  regions standing in for descendants the budget left out (RegionsSubstituted: 0 when the
  cut is the tolerance's).
Then a 36-frame orbit around the box at a target frame rate of 10 fps records frame times and
tolerances, and the same orbit of the whole model (the filter set to every cell) beside it.
The peer, in the same run: stock ParaView's EGRIDReader and Threshold on I, J, K and ACTNUM of
`--peer-grid` (the full grid in memory), the time to the first image of the same box and its
resident memory."""
import argparse
import json
import os
import platform
import time

import numpy as np
from paraview import simple

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", required=True)
parser.add_argument("--models", nargs="+", required=True)
parser.add_argument("--peer-grid", default="")
parser.add_argument("--out", default="bench/results/range")
args = parser.parse_args()

simple.LoadPlugin(args.plugin, remote=False, ns=vars(simple))
WIDTH, HEIGHT = 1280, 720


def rss_mb():
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return 0.0


def ranges(nx, ny, nk):
    return [
        ("box", [nx // 4 + 1, 3 * nx // 4, ny // 4 + 1, 3 * ny // 4, nk // 4 + 1, 3 * nk // 4]),
        ("islice", [nx // 2, nx // 2, 1, ny, 1, nk]),
        ("jslice", [1, nx, ny // 3, ny // 3, 1, nk]),
        ("kslab", [1, nx, 1, ny, nk // 2, nk // 2 + 1]),
    ]


def place(view, bounds, direction, zoom=1.0):
    centre = [(bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2, (bounds[4] + bounds[5]) / 2]
    size = max(bounds[1] - bounds[0], bounds[3] - bounds[2])
    norm = sum(d * d for d in direction) ** 0.5
    view.CameraFocalPoint = centre
    view.CameraPosition = [centre[i] + 1.6 * size * direction[i] / norm / zoom for i in range(3)]
    view.CameraViewUp = [0, 0, 1]


def readout(display, name):
    display.UpdatePropertyInformation()
    return display.GetPropertyValue(name)


def cpu_name():
    with open("/proc/cpuinfo") as info:
        for line in info:
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return platform.processor()


rows = []
view = simple.CreateRenderView()
view.ViewSize = [WIDTH, HEIGHT]
view.OrientationAxesVisibility = 0
for path in args.models:
    reader = simple.OpenDataFile(path)
    subset = simple.MultiresolutionExtractSubset(Input=reader)
    subset.UpdatePipelineInformation()
    voi_range = list(subset.GetPropertyValue("VOIRange"))
    nx, ny, nk = voi_range[1], voi_range[5], voi_range[9]
    display = simple.Show(subset, view)
    display.MemoryBudgetMB = 1024
    display.PaintBy = "Property"
    simple.ColorBy(display, ("CELLS", "PORO"))
    display.WaitForDetailMs = 120000
    bounds = reader.GetDataInformation().GetBounds()
    simple.Render(view)
    place(view, bounds, [0.6, -0.8, 0.7])
    # The whole model first, as a user sees it before filtering: its tables and meshes in.
    simple.Render(view)
    display.WaitForDetailMs = 0
    for tag, voi in ranges(nx, ny, nk):
        subset.VOI = voi
        start = time.perf_counter()
        simple.Render(view)
        first = time.perf_counter() - start
        first_regions = readout(display, "RegionsDrawn")
        renders = 1
        while readout(display, "LoadsPending") and time.perf_counter() - start < 600:
            simple.Render(view)
            renders += 1
        full = time.perf_counter() - start
        row = {
            "model": os.path.basename(path), "dims": [nx, ny, nk], "range": tag, "voi": voi,
            "first_image_s": round(first, 3), "first_regions": first_regions,
            "full_detail_s": round(full, 3), "renders": renders,
            "regions": readout(display, "RegionsDrawn"), "triangles": readout(display, "TrianglesDrawn"),
            "substituted": readout(display, "RegionsSubstituted"),
            "resident_mb": round(readout(display, "ResidentMB"), 1), "budget_mb": 1024,
            "process_rss_mb": round(rss_mb(), 1),
        }
        print(json.dumps(row), flush=True)
        rows.append(row)
    # Flying the box at a target frame rate, and the whole model along the same path.
    display.TargetFrameRate = 10
    for tag, voi in (("box", ranges(nx, ny, nk)[0][1]), ("whole model", [1, nx, 1, ny, 1, nk])):
        subset.VOI = voi
        place(view, bounds, [1, 0, 0.7])
        display.WaitForDetailMs = 120000
        simple.Render(view)
        display.WaitForDetailMs = 0
        frames, tolerances = [], []
        for step in range(36):
            angle = 2 * np.pi * step / 36
            place(view, bounds, [np.cos(angle), np.sin(angle), 0.7])
            start = time.perf_counter()
            simple.Render(view)
            frames.append(1000 * (time.perf_counter() - start))
            tolerances.append(readout(display, "CurrentTolerance"))
        row = {"model": os.path.basename(path), "dims": [nx, ny, nk], "range": f"{tag} orbit, 10 fps target",
               "frame_ms_p50": round(float(np.percentile(frames, 50)), 1),
               "frame_ms_p95": round(float(np.percentile(frames, 95)), 1),
               "tolerance_px_p50": round(float(np.percentile(tolerances, 50)), 2),
               "resident_mb": round(readout(display, "ResidentMB"), 1), "budget_mb": 1024}
        print(json.dumps(row), flush=True)
        rows.append(row)
    display.TargetFrameRate = 0
    simple.Delete(subset)
    simple.Delete(reader)

if args.peer_grid:
    before = rss_mb()
    start = time.perf_counter()
    grid = simple.EGRIDReader(FileName=args.peer_grid)
    grid.UpdatePipeline()
    info = grid.GetDataInformation()
    dims = [int(grid.CellData[a].GetRange()[1]) for a in ("I", "J", "K")]
    voi = ranges(*dims)[0][1]
    out = grid
    for axis, name in enumerate(("I", "J", "K")):
        out = simple.Threshold(Input=out, Scalars=["CELLS", name], LowerThreshold=voi[2 * axis],
                               UpperThreshold=voi[2 * axis + 1])
    out = simple.Threshold(Input=out, Scalars=["CELLS", "ACTNUM"], LowerThreshold=1, UpperThreshold=3)
    shown = simple.Show(out, view)
    simple.ColorBy(shown, ("CELLS", "PORO"))
    place(view, info.GetBounds(), [0.6, -0.8, 0.7])
    simple.Render(view)
    first = time.perf_counter() - start
    # A filter change: the slab of the box one layer lower.
    start = time.perf_counter()
    out.Input.LowerThreshold = voi[4] + 1
    simple.Render(view)
    change = time.perf_counter() - start
    row = {"model": os.path.basename(args.peer_grid), "dims": dims, "range": "box, stock Threshold (peer)",
           "voi": voi, "open_and_first_image_s": round(first, 3), "filter_change_s": round(change, 3),
           "process_rss_added_mb": round(rss_mb() - before, 1)}
    print(json.dumps(row), flush=True)
    rows.append(row)

machine = {"cpu": cpu_name(), "cores": os.cpu_count(),
           "memory_gb": round(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30, 1)}
with open(args.out + ".json", "w") as out_file:
    json.dump({"machine": machine, "rows": rows}, out_file, indent=1)
with open(args.out + ".md", "w") as md:
    md.write(f"# I/J/K range filter\n\nMachine: {machine['cpu']}, {machine['cores']} cores, "
             f"{machine['memory_gb']} GB, Mesa llvmpipe; 1280x720, PORO, 1 px, budget 1024 MB.\n\n")
    md.write("| model | range | first image (s) | full detail (s) | regions | substituted | triangles | resident MB |\n")
    md.write("|---|---|---|---|---|---|---|---|\n")
    for r in rows:
        if "first_image_s" in r:
            md.write(f"| {r['model']} | {r['range']} {r['voi']} | {r['first_image_s']} | {r['full_detail_s']} | "
                     f"{r['regions']} | {r['substituted']} | {r['triangles']} | {r['resident_mb']} |\n")
    md.write("\n| model | flight | frame p50 (ms) | frame p95 (ms) | tolerance p50 (px) | resident MB |\n"
             "|---|---|---|---|---|---|\n")
    for r in rows:
        if "frame_ms_p50" in r:
            md.write(f"| {r['model']} | {r['range']} | {r['frame_ms_p50']} | {r['frame_ms_p95']} | "
                     f"{r['tolerance_px_p50']} | {r['resident_mb']} |\n")
    for r in rows:
        if "open_and_first_image_s" in r:
            md.write(f"\nPeer: stock ParaView on {r['model']} {r['dims']}: EGRIDReader + Threshold of the box "
                     f"{r['voi']}, open to first image {r['open_and_first_image_s']} s, a filter change "
                     f"{r['filter_change_s']} s, {r['process_rss_added_mb']} MB added to the process.\n")
