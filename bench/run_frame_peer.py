"""The view benchmark's frames drawn by stock ParaView, same triangles, same camera, run with
pvpython:

  pvpython bench/run_frame_peer.py --plugin PLUGIN.so --cut build/bin/bench_frame_cut \
      --model MODEL.resmr --bench bench/results/view-quality.json --key synth:1000x1000x100 \
      [--count 4] [--out bench/results/frame_peer]

For the `count` slowest sampled frames of the benchmark's idle path (none drawing stand-ins), the
frame's ideal cut at the tolerance the controller chose for it is written by bench_frame_cut
(the parts the Multiresolution Surface draws, every region resident) and drawn by stock
ParaView's Surface representation, back faces culled as ours are, in one colour and coloured
by a cell array, at the moving frame's resolution (the render scale it was drawn at) and at the
full 1280x720. The Multiresolution Surface draws the same cut, at a fixed tolerance, at both
sizes in the same run. Each drawing is the median and p99 of 20 frames, the camera nudged
between them. What it shows: what the triangles alone cost this machine's renderer, whoever
draws them."""
import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time

from paraview import simple

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", required=True)
parser.add_argument("--cut", required=True, help="bench_frame_cut")
parser.add_argument("--model", required=True)
parser.add_argument("--bench", required=True, help="a view benchmark's JSON (run_view_bench.py)")
parser.add_argument("--key", required=True, help="the model's name there, e.g. synth:1000x1000x100")
parser.add_argument("--count", type=int, default=4)
parser.add_argument("--frames", type=int, default=20)
parser.add_argument("--out", default="bench/results/frame_peer")
args = parser.parse_args()

WIDTH, HEIGHT = 1280, 720
simple.LoadPlugin(args.plugin, ns=globals())
bench = json.load(open(args.bench))
entry = next(m for m in bench["models"] if m["model"] == args.key and m["load"] == "idle")
frames = entry["frames"]
# The slowest sampled frames of the path (all meshes in: no frame still loading).
loaded = [s for s in entry["quality"] if not frames[s["frame"]].get("substituted")]
samples = sorted(loaded, key=lambda s: -frames[s["frame"]]["seconds"])[:args.count]


def percentile(values, p):
    values = sorted(values)
    return values[min(len(values) - 1, int(round(p / 100 * (len(values) - 1))))]


def timed(view, sample):
    """Median and p99 ms of `args.frames` renders, the camera nudged a little each time."""
    times = []
    for n in range(args.frames + 2):
        set_camera(view, sample, 0.01 * (n % 2))
        start = time.perf_counter()
        simple.Render(view)
        if n >= 2:
            times.append(1000 * (time.perf_counter() - start))
    return round(percentile(times, 50), 1), round(percentile(times, 99), 1)


def set_camera(view, sample, azimuth=0.0):
    camera = view.GetActiveCamera()
    camera.SetPosition(sample["position"])
    camera.SetFocalPoint(sample["focal"])
    camera.SetViewUp(0, 0, 1)
    camera.Azimuth(azimuth)


def new_view(width, height):
    view = simple.CreateRenderView()
    view.ViewSize = [width, height]
    view.OrientationAxesVisibility = 0
    view.UseFXAA = 0
    return view


def export_cut(view, sample, path):
    """Writes the frame's cut (bench_frame_cut) seen from `view` at full size."""
    set_camera(view, sample)
    simple.Render(view)
    camera = view.GetActiveCamera()
    matrix = camera.GetCompositeProjectionTransformMatrix(WIDTH / HEIGHT, -1, 1)
    values = [matrix.GetElement(r, c) for r in range(4) for c in range(4)]
    command = [args.cut, args.model, path, repr(sample["tolerance"]), str(HEIGHT), repr(camera.GetViewAngle()),
               repr(camera.GetClippingRange()[0])] + [repr(v) for v in camera.GetPosition()] + \
              [repr(v) for v in camera.GetDirectionOfProjection()] + [repr(v) for v in values]
    return json.loads(subprocess.run(command, check=True, capture_output=True, text=True).stdout)


# paraview.simple resets the camera on a session's first render: spend it on an empty view.
simple.Render(new_view(64, 64))
rows = []
scratch = tempfile.mkdtemp(prefix="frame_peer_")
for sample in samples:
    frame = frames[sample["frame"]]
    scale = sample.get("render_scale", 1) or 1
    reduced = (int(round(WIDTH * scale)), int(round(HEIGHT * scale)))
    row = {"frame": sample["frame"], "tolerance_px": round(sample["tolerance"], 2), "render_scale": scale,
           "bench_ms": round(1000 * frame["seconds"], 1), "bench_triangles": int(frame["triangles"])}
    # Ours: the same cut at a fixed tolerance (the controller off), every region loaded; at the
    # reduced size the tolerance halves with the viewport, so the cut stays the same.
    for size, key in ((reduced, "reduced"), ((WIDTH, HEIGHT), "full")):
        view = new_view(*size)
        reader = simple.OpenDataFile(args.model)
        display = simple.Show(reader, view)
        display.MemoryBudgetMB = 8192
        simple.ColorBy(display, ("CELLS", "PORO"))
        display.PixelTolerance = sample["tolerance"] * size[1] / HEIGHT
        display.WaitForDetailMs = 600000
        set_camera(view, sample)
        simple.Render(view)
        display.WaitForDetailMs = 0
        display.UpdatePropertyInformation()
        row[f"ours_{key}_triangles"] = int(display.GetPropertyValue("TrianglesDrawn"))
        row[f"ours_{key}_ms"] = timed(view, sample)
        if key == "full":
            path = os.path.join(scratch, "cut.vtk")
            row["cut"] = export_cut(view, sample, path)
        simple.Delete(display)
        simple.Delete(reader)
        simple.Delete(view)
    # Stock ParaView: the cut's triangles as polydata, back faces culled.
    for size, key in ((reduced, "reduced"), ((WIDTH, HEIGHT), "full")):
        view = new_view(*size)
        polydata = simple.LegacyVTKReader(FileNames=[path])
        shown = simple.Show(polydata, view)
        shown.SetRepresentationType("Surface")
        shown.BackfaceRepresentation = "Cull Backface"
        simple.ColorBy(shown, None)
        row[f"stock_{key}_solid_ms"] = timed(view, sample)
        simple.ColorBy(shown, ("CELLS", "cell"))
        row[f"stock_{key}_cells_ms"] = timed(view, sample)
        simple.Delete(shown)
        simple.Delete(polydata)
        simple.Delete(view)
    os.remove(path)
    print(json.dumps(row), flush=True)
    rows.append(row)
os.rmdir(scratch)

cpu = [l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")]
result = {"model": args.key, "bench": os.path.basename(args.bench), "date": time.strftime("%Y-%m-%d %H:%M"),
          "machine": "%s, %d cores, llvmpipe" % (cpu[0] if cpu else platform.processor(), os.cpu_count()),
          "frames_timed": args.frames, "rows": rows}
runs = []
if os.path.exists(args.out + ".json"):
    runs = [r for r in json.load(open(args.out + ".json")) if r["model"] != args.key]
runs.append(result)
with open(args.out + ".json", "w") as f:
    json.dump(runs, f, indent=1)

lines = ["# The benchmark's frames drawn by stock ParaView", "",
         "Generated by `bench/run_frame_peer.py`: the slowest sampled frames of the view benchmark's idle path (no "
         "stand-ins); each frame's cut at the controller's tolerance (every region loaded) drawn by the Multiresolution "
         "Surface at that fixed tolerance (PORO, lit by the light kit, grid lines) and, as polydata of the same "
         "triangles, by stock ParaView's Surface (back faces culled, light kit; one colour, or coloured by a cell "
         "array), at the moving frame's reduced size and at 1280x720. Median / p99 of %d frames, the camera nudged "
         "between them. 'path': the frame's time on the benchmark's path." % args.frames, ""]
for r in runs:
    lines += ["## %s (%s)" % (r["model"], r["bench"]), "", "%s, %s" % (r["date"], r["machine"]), "",
              "| frame | tolerance px | triangles | path ms | size | ours ms | stock, one colour ms | "
              "stock, cell colours ms |", "|---|---|---|---|---|---|---|---|"]
    for row in r["rows"]:
        scale = row["render_scale"]
        for key, size in (("reduced", "%dx%d" % (round(WIDTH * scale), round(HEIGHT * scale))),
                          ("full", "%dx%d" % (WIDTH, HEIGHT))):
            lines.append("| %d | %.1f | %s | %.0f | %s | %.0f / %.0f | %.0f / %.0f | %.0f / %.0f |" % (
                row["frame"], row["tolerance_px"], format(row["cut"]["triangles"], ","), row["bench_ms"], size,
                *row[f"ours_{key}_ms"], *row[f"stock_{key}_solid_ms"], *row[f"stock_{key}_cells_ms"]))
    lines.append("")
with open(args.out + ".md", "w") as f:
    f.write("\n".join(lines))
