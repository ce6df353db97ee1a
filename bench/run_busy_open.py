"""Opening a model on a busy machine, run with pvpython:

  pvpython bench/run_busy_open.py --plugin PLUGIN.so --model MODEL.resmr --label "this build" \
      [--spinners 2] [--seconds 40] [--out bench/results/busy_open]

Starts --spinners processes that spin at normal priority (a workstation running a simulation),
opens the model in the Multiresolution Surface coloured by PORO (10 FPS target, 512 MB,
1280x720) and turns the camera a little every frame for --seconds. Every 25th frame records
the time since the open began, the share of pixels in saturated colours (the lookup table's:
0% while the surface is drawn in the solid colour, before the property table arrives),
whether loads are pending and the resident MB. Each run is stored under its --label in
OUT.json (a run with the same label replaces it); OUT.md sets them side by side."""
import argparse
import os
import sys
import time

import numpy as np
from paraview import simple

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "Testing", "Python"))
import resmr_testing as rt  # noqa: E402
from labelled_runs import store_run  # noqa: E402
from view_quality import BusyLoad  # noqa: E402

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", required=True)
parser.add_argument("--model", required=True)
parser.add_argument("--label", required=True)
parser.add_argument("--spinners", type=int, default=2)
parser.add_argument("--seconds", type=float, default=40)
parser.add_argument("--out", default=os.path.join(HERE, "results", "busy_open"))
args = parser.parse_args()

simple.LoadPlugin(args.plugin, ns=globals())
samples = []
with BusyLoad(args.spinners):
    view = simple.CreateRenderView()
    view.ViewSize = [1280, 720]
    view.OrientationAxesVisibility = 0
    view.UseFXAA = 0
    start = time.perf_counter()
    reader = simple.OpenDataFile(args.model)
    display = simple.Show(reader, view)
    simple.ColorBy(display, ("CELLS", "PORO"))
    display.TargetFrameRate = 10
    display.MemoryBudgetMB = 512
    camera = view.GetActiveCamera()
    camera.Elevation(40)
    frame = 0
    while time.perf_counter() - start < args.seconds:
        camera.Azimuth(0.2)
        simple.Render(view)
        if frame % 25 == 0:
            display.UpdatePropertyInformation()
            image = rt.capture_rgb(view, os.path.join(HERE, "scratch", "busy_open.png"), 1280, 720).astype(int)
            saturated = float(np.mean(image.max(axis=2) - image.min(axis=2) > 40))
            samples.append({"frame": frame, "seconds": round(time.perf_counter() - start, 2),
                            "saturated": round(saturated, 4), "pending": int(display.GetPropertyValue("LoadsPending")),
                            "resident_mb": round(display.GetPropertyValue("ResidentMB"), 1)})
            print(samples[-1], flush=True)
        frame += 1


def first(condition):
    hit = next((s for s in samples if condition(s)), None)
    return hit["seconds"] if hit else None


run = {"label": args.label, "model": os.path.basename(args.model), "spinners": args.spinners,
       "date": time.strftime("%Y-%m-%d %H:%M"), "cpu": os.cpu_count(), "samples": samples,
       "first_sample_s": samples[0]["seconds"] if samples else None,
       "colours_s": first(lambda s: s["saturated"] > 0.005),
       "loaded_s": first(lambda s: s["pending"] == 0)}
runs = store_run(args.out + ".json", run)
lines = ["# Opening a model on a busy machine", "",
         "`bench/run_busy_open.py`: the model opened while other processes spin on every core, coloured by PORO, "
         "10 FPS target, 1280x720, 512 MB; seconds from the open to the first frame, to the first frame in the "
         "lookup table's colours (not the solid colour) and to the first frame with nothing left to load "
         "(sampled every 25 frames).", "",
         "| build | model | spinners | date | first frame s | colours s | all loaded s |", "|---|---|---|---|---|---|---|"]
fmt = lambda v: "-" if v is None else f"{v:.1f}"  # noqa: E731
for r in runs:
    lines.append(f"| {r['label']} | {r['model']} | {r['spinners']} on {r['cpu']} cores | {r['date']} | "
                 f"{fmt(r['first_sample_s'])} | {fmt(r['colours_s'])} | {fmt(r['loaded_s'])} |")
with open(args.out + ".md", "w") as out:
    out.write("\n".join(lines) + "\n")
