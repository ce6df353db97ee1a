"""I/J/K range and property filters (Multiresolution Extract Subset, Multiresolution
Threshold) on large models, run with pvpython:

  pvpython bench/run_filter_bench.py --plugin PLUGIN.so --models A.resmr B.resmr \
      [--peer-grid GRID.EGRID] [--out bench/results/filters]

Each model (with its property file) is shown at 1280x720, coloured by PORO, lit, at the
default 1 px tolerance and a 1024 MB budget, from an oblique overview, through Multiresolution
Extract Subset and then Multiresolution Threshold. Each filter change below is measured as:
- first image: the wall time from the change to the end of the first render after it, waiting
  for no detail (what a user sees first; a time step renders the view itself, as the time
  toolbar does, other changes are followed by one render);
- full detail: renders at the GUI's refresh cadence (none waiting for detail; the next one
  the surface's RefreshWaitMs after the last, as ParaView's view is refreshed while loads are
  pending: as long as that frame took while the loaders read, 30 ms when only copies to the
  GPU remain) until no load is pending, the wall time from the change to the first render with
  nothing pending;
- memory: the surface's resident MB (CPU buffers + GPU copies) against the budget, and the
  regions standing in for descendants the budget left out (RegionsSubstituted: 0 when the
  picture is the tolerance's).
Changes: the range to a box, an I slice, a J slice and a K slab (VOI from the model's
dimensions); then, the range back to every cell, the property filter to the upper half of
PORO's range, to SWAT from 0.5 to 1 (the water-swept cells) at the first report step, and the
time step to the last (the filtered set moves with the water). Then 36-frame orbits at a target
frame rate of 10 fps record frame times and tolerances: of the box, of the SWAT filter at the
last step, and of the whole model beside them.
The peer, in the same run: stock ParaView's EGRIDReader and Threshold of `--peer-grid` (the
full grid in memory): on I, J, K and ACTNUM (the box), and on PORO (its upper half): open to
first image, a filter change, and memory added."""
import argparse
import json
import os
import time

import bench_machine
import numpy as np
from paraview import simple

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", required=True)
parser.add_argument("--models", nargs="+", required=True)
parser.add_argument("--peer-grid", default="")
parser.add_argument("--out", default="bench/results/filters")
parser.add_argument("--append", action="store_true", help="add to OUT.json's rows (models run apart, same machine)")
args = parser.parse_args()

simple.LoadPlugin(args.plugin, remote=False, ns=vars(simple))
WIDTH, HEIGHT = 1280, 720
BUDGET_MB = 1024


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


def measure_change(view, display, change, row):
    """Applies `change`, then times the first image and full detail (see the docstring)."""
    # A change of the animation time renders the view itself (as the time toolbar does in the
    # GUI): the first image is the end of the first render after the change, whoever asks it.
    ends = []
    window = view.GetRenderWindow()
    tag = window.AddObserver("EndEvent", lambda *args: ends.append(time.perf_counter()))
    start = time.perf_counter()
    change()
    if not ends:
        simple.Render(view)
    window.RemoveObserver(tag)
    first = ends[0] - start
    first_regions = readout(display, "RegionsDrawn")
    renders = 1
    while readout(display, "LoadsPending") and time.perf_counter() - start < 600:
        time.sleep(readout(display, "RefreshWaitMs") / 1000)
        simple.Render(view)
        renders += 1
    row.update({
        "first_image_s": round(first, 3), "first_regions": first_regions,
        "full_detail_s": round(time.perf_counter() - start, 3), "renders": renders,
        "regions": readout(display, "RegionsDrawn"), "triangles": readout(display, "TrianglesDrawn"),
        "substituted": readout(display, "RegionsSubstituted"),
        "resident_mb": round(readout(display, "ResidentMB"), 1), "budget_mb": BUDGET_MB,
        "process_rss_mb": round(rss_mb(), 1),
    })
    print(json.dumps(row), flush=True)
    return row


def orbit(view, display, bounds, row):
    """36 frames around the model at a target frame rate of 10 fps, after a still full-detail frame."""
    display.TargetFrameRate = 10
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
    display.TargetFrameRate = 0
    row.update({"frame_ms_p50": round(float(np.percentile(frames, 50)), 1),
                "frame_ms_p95": round(float(np.percentile(frames, 95)), 1),
                "tolerance_px_p50": round(float(np.percentile(tolerances, 50)), 2),
                "resident_mb": round(readout(display, "ResidentMB"), 1), "budget_mb": BUDGET_MB})
    print(json.dumps(row), flush=True)
    return row


def bench_model(path, view, rows):
    reader = simple.OpenDataFile(path)
    reader.UpdatePipeline()
    scene = simple.GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    times = list(reader.TimestepValues) if reader.TimestepValues else [0.0]
    scene.AnimationTime = times[0]
    subset = simple.MultiresolutionExtractSubset(Input=reader)
    subset.UpdatePipelineInformation()
    voi_range = list(subset.GetPropertyValue("VOIRange"))
    nx, ny, nk = voi_range[1], voi_range[5], voi_range[9]
    whole = [1, nx, 1, ny, 1, nk]
    threshold = simple.MultiresolutionThreshold(Input=subset)
    threshold.Scalars = ["CELLS", "PORO"]
    low, high = reader.CellData["PORO"].GetRange()
    threshold.LowerThreshold, threshold.UpperThreshold = low - 1, high + 1  # every cell
    display = simple.Show(threshold, view)
    display.MemoryBudgetMB = BUDGET_MB
    display.PaintBy = "Property"
    simple.ColorBy(display, ("CELLS", "PORO"))
    display.WaitForDetailMs = 120000
    bounds = reader.GetDataInformation().GetBounds()
    simple.Render(view)
    place(view, bounds, [0.6, -0.8, 0.7])
    # The whole model first, as a user sees it before filtering: its tables and meshes in.
    simple.Render(view)
    display.WaitForDetailMs = 0
    model = {"model": os.path.basename(path), "dims": [nx, ny, nk]}

    def set_voi(voi):
        return lambda: setattr(subset, "VOI", voi)

    for tag, voi in ranges(nx, ny, nk):
        rows.append(measure_change(view, display, set_voi(voi), dict(model, change=f"range {tag} {voi}")))
    rows.append(orbit(view, display, bounds, dict(model, change="box orbit, 10 fps target")))
    subset.VOI = whole
    display.WaitForDetailMs = 120000
    place(view, bounds, [0.6, -0.8, 0.7])
    simple.Render(view)
    display.WaitForDetailMs = 0
    middle = low + 0.5 * (high - low)

    def set_filter(array, lower, upper):
        def apply():
            threshold.Scalars = ["CELLS", array]
            threshold.LowerThreshold, threshold.UpperThreshold = lower, upper
        return apply

    rows.append(measure_change(view, display, set_filter("PORO", middle, high),
                               dict(model, change=f"PORO {middle:.4g} to {high:.4g}")))
    has_swat = "SWAT" in reader.CellData.keys()
    if has_swat:
        # Coloured by SWAT first, its table in: what is timed is the filter change alone.
        simple.ColorBy(display, ("CELLS", "SWAT"))
        display.WaitForDetailMs = 120000
        simple.Render(view)
        display.WaitForDetailMs = 0
        rows.append(measure_change(view, display, set_filter("SWAT", 0.5, 1.0),
                                   dict(model, change=f"SWAT 0.5 to 1, day {times[0]:g}")))
        rows.append(measure_change(view, display, lambda: setattr(scene, "AnimationTime", times[-1]),
                                   dict(model, change=f"SWAT 0.5 to 1, time step to day {times[-1]:g}")))
        rows.append(orbit(view, display, bounds, dict(model, change="SWAT 0.5 to 1 orbit, 10 fps target")))
    # The whole model unfiltered (the reader itself) along the same path.
    simple.Hide(threshold, view)
    plain = simple.Show(reader, view)
    plain.MemoryBudgetMB = BUDGET_MB
    simple.ColorBy(plain, ("CELLS", "SWAT" if has_swat else "PORO"))
    rows.append(orbit(view, plain, bounds, dict(model, change="whole model orbit, 10 fps target")))
    scene.AnimationTime = times[0]
    for proxy in (threshold, subset, reader):
        simple.Delete(proxy)


def bench_peer(path, view, rows):
    """Stock ParaView on the full grid: Threshold of the box (I, J, K, ACTNUM), then of PORO."""
    before = rss_mb()
    start = time.perf_counter()
    grid = simple.EGRIDReader(FileName=path)
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
    start = time.perf_counter()
    out.Input.LowerThreshold = voi[4] + 1  # the slab of the box one layer lower
    simple.Render(view)
    change = time.perf_counter() - start
    rows.append({"model": os.path.basename(path), "dims": dims, "change": f"stock Threshold, box {voi} (peer)",
                 "open_and_first_image_s": round(first, 3), "filter_change_s": round(change, 3),
                 "process_rss_added_mb": round(rss_mb() - before, 1)})
    print(json.dumps(rows[-1]), flush=True)
    simple.Hide(out, view)
    low, high = grid.CellData["PORO"].GetRange()
    start = time.perf_counter()
    poro = simple.Threshold(Input=grid, Scalars=["CELLS", "PORO"], LowerThreshold=low + 0.5 * (high - low),
                            UpperThreshold=high)
    shown = simple.Show(poro, view)
    simple.ColorBy(shown, ("CELLS", "PORO"))
    simple.Render(view)
    first = time.perf_counter() - start
    start = time.perf_counter()
    poro.LowerThreshold = low + 0.6 * (high - low)
    simple.Render(view)
    change = time.perf_counter() - start
    rows.append({"model": os.path.basename(path), "dims": dims, "change": "stock Threshold, PORO upper half (peer)",
                 "open_and_first_image_s": round(first, 3), "filter_change_s": round(change, 3),
                 "process_rss_added_mb": round(rss_mb() - before, 1)})
    print(json.dumps(rows[-1]), flush=True)


def write_results(rows):
    if args.append and os.path.exists(args.out + ".json"):
        with open(args.out + ".json") as earlier:
            rows = json.load(earlier)["rows"] + rows
    machine = bench_machine.machine()
    with open(args.out + ".json", "w") as out_file:
        json.dump({"machine": machine, "rows": rows}, out_file, indent=1)
    with open(args.out + ".md", "w") as md:
        md.write(f"# I/J/K range and property filters\n\nMachine: {machine['cpu']}, {machine['cores']} cores, "
                 f"{machine['memory_gb']} GB, Mesa llvmpipe; 1280x720, 1 px, budget {BUDGET_MB} MB.\n\n")
        md.write("| model | change | first image (s) | full detail (s) | regions | substituted | triangles "
                 "| resident MB |\n|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            if "first_image_s" in r:
                md.write(f"| {r['model']} | {r['change']} | {r['first_image_s']} | {r['full_detail_s']} | "
                         f"{r['regions']} | {r['substituted']} | {r['triangles']} | {r['resident_mb']} |\n")
        md.write("\n| model | flight | frame p50 (ms) | frame p95 (ms) | tolerance p50 (px) | resident MB |\n"
                 "|---|---|---|---|---|---|\n")
        for r in rows:
            if "frame_ms_p50" in r:
                md.write(f"| {r['model']} | {r['change']} | {r['frame_ms_p50']} | {r['frame_ms_p95']} | "
                         f"{r['tolerance_px_p50']} | {r['resident_mb']} |\n")
        for r in rows:
            if "open_and_first_image_s" in r:
                md.write(f"\nPeer: stock ParaView on {r['model']} {r['dims']}, EGRIDReader + {r['change']}: open to "
                         f"first image {r['open_and_first_image_s']} s, a filter change {r['filter_change_s']} s, "
                         f"{r['process_rss_added_mb']} MB added to the process.\n")


rows = []
view = simple.CreateRenderView()
view.ViewSize = [WIDTH, HEIGHT]
view.OrientationAxesVisibility = 0
for model_path in args.models:
    bench_model(model_path, view, rows)
if args.peer_grid:
    bench_peer(args.peer_grid, view, rows)
write_results(rows)
