"""Pick latency on the Multiresolution Surface, run with pvpython:

  pvpython bench/run_pick_bench.py --plugin PLUGIN.so --models A.resmr B.resmr \
      [--picks 100] [--out bench/results/pick]

Each model (with its property file) is shown at 1280x720, coloured by PORO, lit, at the
default 1 px tolerance with every mesh loaded, from an oblique overview; then `picks` random
pixels the model covers are picked as the GUI's hover does (resmr_inspect.PickCell: PickAt, the
pick pass drawn from the last frame with no new render, the readouts pulled), each timed from
the request to the answer in Python. A render of the same view is timed in the same run (what a
pick that waited for a frame would cost). Memory: the process's resident
set before the first pick and after the last (heap: RssAnon; the property file's mapped pages
the picks touched, RssFile, are the page cache's and reclaimable), and the pick target's GPU
bytes (one pixel)."""
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
parser.add_argument("--picks", type=int, default=100)
parser.add_argument("--out", default="bench/results/pick")
parser.add_argument("--drop-caches", action="store_true",
                    help="empty the page cache before each model (root): its files' first picks read the disk")
args = parser.parse_args()

simple.LoadPlugin(args.plugin, remote=False, ns=vars(simple))
import resmr_inspect  # noqa: E402 (the plugin carries it)

WIDTH, HEIGHT = 1280, 720
rng = np.random.default_rng(3)


def rss_mb(kind="RssAnon"):
    """Resident memory of the process, MB: RssAnon (heap, the memory picking could add) or
    RssFile (mapped files' pages, the page cache's: reclaimable)."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(kind + ":"):
                return int(line.split()[1]) / 1024
    return 0.0


def percentile(values, p):
    return float(np.percentile(np.asarray(values), p))


simple.Render(simple.CreateRenderView())  # paraview.simple resets the camera on its first render
rows = []
for path in args.models:
    if args.drop_caches:
        os.sync()
        with open("/proc/sys/vm/drop_caches", "w") as caches:
            caches.write("3\n")
    view = simple.CreateRenderView()
    view.ViewSize = [WIDTH, HEIGHT]
    view.OrientationAxesVisibility = 0
    view.UseFXAA = 0
    view.Background = [0.0, 0.0, 0.0]  # so that the Cell Id colouring's covered pixels are the non-black ones
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    reader = simple.OpenDataFile(path)
    display = simple.Show(reader, view)
    display.MemoryBudgetMB = 2048
    simple.ColorBy(display, ("CELLS", "PORO"))
    display.WaitForDetailMs = 600000
    view.ResetCamera(False)
    camera = view.GetActiveCamera()
    camera.Elevation(35)
    camera.Azimuth(20)
    simple.Render(view)
    display.WaitForDetailMs = 0
    # Covered pixels, from the Cell Id colouring of the same frame.
    display.PaintBy = "Cell Id"
    simple.Render(view)
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter
    grab = vtkWindowToImageFilter()
    grab.SetInput(view.GetRenderWindow())
    grab.ShouldRerenderOff()
    grab.ReadFrontBufferOff()
    grab.Update()
    pixels = vtk_to_numpy(grab.GetOutput().GetPointData().GetScalars())[:, :3].astype(np.int64)
    covered = np.nonzero(pixels.sum(axis=1) > 0)[0]
    display.PaintBy = "Property"
    simple.Render(view)
    plain = []
    for _ in range(20):
        start = time.perf_counter()
        simple.Render(view)
        plain.append(1000 * (time.perf_counter() - start))
    before, before_file = rss_mb(), rss_mb("RssFile")
    latencies, named = [], 0
    for n in rng.choice(len(covered), args.picks, replace=False):
        x, y = int(covered[n] % WIDTH), int(covered[n] // WIDTH)
        start = time.perf_counter()
        cell = resmr_inspect.PickCell(x, y, view, display)
        latencies.append(1000 * (time.perf_counter() - start))
        named += cell is not None and bool(cell["values"])
    after, after_file = rss_mb(), rss_mb("RssFile")
    display.UpdatePropertyInformation()
    cell = resmr_inspect.PickCell(int(covered[0] % WIDTH), int(covered[0] // WIDTH), view, display)
    row = {"model": os.path.basename(path), "triangles": int(display.GetPropertyValue("TrianglesDrawn")),
           "regions": int(display.GetPropertyValue("RegionsDrawn")),
           "tables_read": len(cell["values"]) if cell else 0,
           "picks": args.picks, "picks_with_values": named,
           "pick_p50_ms": round(percentile(latencies, 50), 1), "pick_p99_ms": round(percentile(latencies, 99), 1),
           "render_p50_ms": round(percentile(plain, 50), 1), "render_p99_ms": round(percentile(plain, 99), 1),
           "rss_before_mb": round(before, 1), "rss_after_mb": round(after, 1),
           "rss_added_mb": round(after - before, 1), "file_pages_added_mb": round(after_file - before_file, 1),
           "gpu_bytes": 16 + 4}
    print(json.dumps(row), flush=True)
    rows.append(row)
    simple.Delete(display)
    simple.Delete(reader)
    simple.Delete(view)

cpu = [l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")]
result = {"date": time.strftime("%Y-%m-%d %H:%M"), "view": [WIDTH, HEIGHT], "page_cache_dropped": args.drop_caches,
          "machine": "%s, %d cores, llvmpipe" % (cpu[0] if cpu else platform.processor(), os.cpu_count()),
          "rows": rows}
with open(args.out + ".json", "w") as f:
    json.dump(result, f, indent=1)
lines = ["# Pick latency", "",
         "Generated by `bench/run_pick_bench.py` (%s, %s): each model at 1280x720, PORO, lit, 1 px, every mesh "
         "loaded; %d random covered pixels picked as the GUI's hover does (resmr_inspect.PickCell: the request, "
         "the pick pass drawn from the last frame, no new render, the answer pulled), beside the same view "
         "rendered (what a pick that waited for a frame would cost). Memory: heap (RssAnon) before the first pick and "
         "after the last; the property file's pages the picks mapped (RssFile) are the page cache's.%s" % (
             result["date"], result["machine"], args.picks,
             " The page cache was emptied before each model: the files' pages come from the disk at their first read."
             if args.drop_caches else ""), "",
         "| model | regions, triangles | tables read a pick | pick p50 / p99 ms | a render p50 / p99 ms | "
         "picks with values | heap added MB | file pages added MB |", "|---|---|---|---|---|---|---|---|"]
for r in rows:
    lines.append("| %s | %d, %s | %d | %.0f / %.0f | %.0f / %.0f | %d of %d | %.1f | %.1f |" % (
        r["model"], r["regions"], format(r["triangles"], ","), r["tables_read"], r["pick_p50_ms"], r["pick_p99_ms"],
        r["render_p50_ms"], r["render_p99_ms"], r["picks_with_values"], r["picks"], r["rss_added_mb"],
        r["file_pages_added_mb"]))
with open(args.out + ".md", "w") as f:
    f.write("\n".join(lines) + "\n")
