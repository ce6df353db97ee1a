"""Multiresolution Surface memory budget (issue 7 point 6): resident memory stays within the
budget over 1,000 frames of a camera path on a 10M-cell model, and the process does not leak.

A synthetic model of 1000 x 1000 x 10 cells (10M; 633k columns, 396 regions) is generated
(`resmr synth`), built (`resmr build`) and its properties added (`resmr add-properties`) once:
the .resmr and .resmrp stay in the temporary folder and later runs reuse them while
`resmr info` reads them with the format version resmr writes now (the EGRID and INIT are
removed). The model is drawn with the
Multiresolution Surface at 400 x 300 pixels, coloured by PORO, at a fixed 1 px tolerance, with
a 128 MB budget, along 1,000 frames: an orbit (40%), a zoom to a close look at the centre (30%)
and a low flight over the whole model (30%: three passes along x, there and back, looking
ahead and down). MemoryBudgetMB bounds the loader's draw buffers (half of it) and the mapper's
GL copies of them (the other half) together, and ResidentMB reports both. The roots take
5.6 MB of them (held without their exact side, as every region whose error shows), and at
1 px the path wants far more than the loader's 64 MB, which are pressed from the first frames.
(With the roots' exact sides held too, 28 MB, the budget had to be 256 MB for the resident set
to turn over; and once, a coarse region whose copy had to be made again found the GPU share
full of finer ones and the frames drew the roots alone: copies later in the frame's order now
give way.) The render thread
never waits for loads (WaitForDetailMs 0), as in interaction. Each frame records the readout
(ResidentMB, LoadsPending, RegionsDrawn, RegionsSubstituted, LastError) and the process's
memory (/proc/self/status: VmRSS, and RssAnon, which leaves out pages of the memory-mapped
.resmr and .resmrp that the kernel keeps as a cache and may drop at any time).

Checks:
- ResidentMB <= budget + OVERHEAD_MB on every frame. The region cache (Core/view/RegionCache.h)
  makes a region resident only if its total then fits its half, after evicting the least
  recently requested regions that neither are roots nor are wanted by the newest frame; the
  roots load whatever the budget, so its bound is max(half, roots' bytes), and the roots
  (measured first: a far view at 64 px wants only them) must take less than the half. The GL
  copies are of regions resident when the frame began (the frame drops the others first) or
  loaded while it drew; so the copies can pass their half only by the regions the loader
  made resident, and the frame drew, while the frame was drawing: OVERHEAD_MB = 8 MB allows
  for about eight of them (0 MB measured). Not counted in ResidentMB, so not bounded by the
  budget: the property table (one float a hash slot: 11 MB here) and its 3D texture, the
  hash offset and normal tables and textures (21 MB), and the loader's decompression scratch.
- The budget was pressed and regions were evicted (only net changes between frames are seen
  from here, so these are lower bounds): resident at 75% of the budget or more by frame 100
  and on 90% of the frames after (the loader's half full, most drawn regions copied);
  ancestors drawn for wanted regions that did not fit (RegionsSubstituted > 0) on half the
  frames; the resident set changed on 30 frames after; the net decreases from one frame to
  the next add up to 1/8 of the budget or more, which only evictions make; loads were still
  pending in the last third.
- No leak. The live heap is RssAnon right after malloc_trim(0) (without the free pages malloc
  keeps, which move RssAnon by tens of MB), sampled every 10th frame from frame 100; growth
  is measured beyond ResidentMB's own (under llvmpipe the GL copies are heap memory of this
  process too), between medians over 100 frames. Within the flight (its first pass against
  the last 100 frames), where the resident set turns over (it stays put through the orbit and
  the zoom), growth < FLY_LEAK_LIMIT_MB = 16 MB (measured 1-2 MB; leaking a region's
  buffers (~0.9 MB) on every load there passes it). Over the path (frames 100-199 against
  the last 100), growth < LEAK_LIMIT_MB = 32 MB; this one is biased low: drawing half a
  million triangles a frame through llvmpipe holds some 80 MB more live heap than the
  flight's 100-300 thousand (measured -77 to -83 MB).
- No LastError on any frame.
The run time, frame times and memory peaks are printed."""
import argparse
import ctypes
import json
import math
import os
import subprocess
import time

import numpy as np

from paraview import simple

import resmr_testing as rt

BUDGET_MB = 128
LEAK_LIMIT_MB = 32
FLY_LEAK_LIMIT_MB = 16
OVERHEAD_MB = 8.0
FRAMES = 1000
SIZE = [400, 300]
TOLERANCE_PX = 1.0
DIMS = (1000, 1000, 10)

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", required=True)
parser.add_argument("--data", default="")
parser.add_argument("--baselines", default="")
parser.add_argument("--temp", default="/tmp")
# For measuring (the test runs with the defaults):
parser.add_argument("--budget", type=int, default=BUDGET_MB)
parser.add_argument("--frames", type=int, default=FRAMES)
parser.add_argument("--tolerance", type=float, default=TOLERANCE_PX)
parser.add_argument("--dims", default="x".join(str(d) for d in DIMS))
parser.add_argument("--explore", action="store_true", help="print every frame; report failures, do not fail")
parser.add_argument("--shots", default="", help="comma-separated frames to save as images")
args = parser.parse_args()
budget = args.budget
rt.load_plugin(args.plugin)
resmr = os.environ["RESMR_EXECUTABLE"]
temp = os.path.join(args.temp, "budget")
os.makedirs(temp, exist_ok=True)
nx, ny, nz = (int(v) for v in args.dims.split("x"))
stem = os.path.join(temp, f"synth_{nx}x{ny}x{nz}")
path = stem + ".resmr"


def memory_mb():
    """(VmRSS, RssAnon) of this process, MB."""
    values = {}
    with open("/proc/self/status") as status:
        for line in status:
            key = line.split(":")[0]
            if key in ("VmRSS", "RssAnon"):
                values[key] = int(line.split()[1]) / 1024
    return values["VmRSS"], values["RssAnon"]


def trimmed_anon_mb():
    """RssAnon after malloc_trim(0) has handed free heap pages back to the system: the memory
    that is in use, without what malloc keeps after frees (tens of MB up and down here)."""
    ctypes.CDLL("libc.so.6").malloc_trim(0)
    return memory_mb()[1]


def format_version(resmr_path):
    """The format version `resmr info` reads in a .resmr, or None."""
    done = subprocess.run([resmr, "info", resmr_path], capture_output=True, text=True)
    return json.loads(done.stdout).get("version") if done.returncode == 0 else None


def cached_files_usable():
    """The kept files exist, read, and have the format this resmr writes (a file of an older
    format may still read, without what the newer one records)."""
    if not (os.path.exists(path) and os.path.exists(stem + ".resmrp")):
        return False
    probe = os.path.join(temp, "probe.resmr")
    subprocess.run([resmr, "build", "synth:8x8x2", "-o", probe, "--quiet"], capture_output=True, check=True)
    current = format_version(probe)
    os.remove(probe)
    return current is not None and format_version(path) == current


start = time.perf_counter()
if cached_files_usable():
    print(f"reusing {path} and its .resmrp")
else:
    grid = stem + ".EGRID"
    for stale in (path, stem + ".resmrp"):
        if os.path.exists(stale):
            os.remove(stale)  # an older format's, or a pair an interrupted run left unmatched
    for command in (["synth", str(nx), str(ny), str(nz), "-o", grid, "--quiet"],
                    ["build", grid, "-o", path, "--quiet"],
                    ["add-properties", path, grid]):
        step = time.perf_counter()
        done = subprocess.run([resmr, *command], capture_output=True, text=True)
        if done.returncode != 0:
            rt.fail(f"resmr {' '.join(command)} failed: {done.stderr.strip()}")
        print(f"resmr {command[0]}: {time.perf_counter() - step:.1f} s", flush=True)
    for leftover in (grid, stem + ".INIT"):
        os.remove(leftover)  # 630 MB that reruns do not need
prepared = time.perf_counter() - start

view = simple.CreateRenderView()
view.ViewSize = SIZE
view.OrientationAxesVisibility = 0
view.EnableRenderOnInteraction = 0
reader = simple.OpenDataFile(path)
display = simple.Show(reader, view)
if display.Representation != "Multiresolution Surface":
    rt.fail(f".resmr shown as {display.Representation}")
display.MemoryBudgetMB = budget
display.TargetFrameRate = 0
simple.ColorBy(display, ("CELLS", "PORO"))

# The roots alone: from the reset camera (twice the model's size away) at 64 px no diamond
# is split.
display.PixelTolerance = 64
display.WaitForDetailMs = 30000
view.ResetCamera(False)
simple.Render(view)
display.UpdatePropertyInformation()
roots_mb = display.GetPropertyValue("ResidentMB")
display.PixelTolerance = args.tolerance
display.WaitForDetailMs = 0
bounds = reader.GetDataInformation().GetBounds()


def camera_path(frames):
    """Orbit (40%), zoom to a close look at the centre (30%), then a low flight over the whole
    model (30%): three passes along x at 30, 50 and 70% of y, there and back, 2% of the
    model's size above its top, looking 3% ahead and down to its middle depth."""
    cx, cy = (bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2
    cz = (bounds[4] + bounds[5]) / 2
    size = max(bounds[1] - bounds[0], bounds[3] - bounds[2])
    cameras = []
    orbit, zoom = int(frames * 0.4), int(frames * 0.3)
    fly = frames - orbit - zoom
    for f in range(orbit):
        a = 2 * math.pi * f / orbit
        cameras.append(((cx + 1.2 * size * math.cos(a), cy + 1.2 * size * math.sin(a), cz + 0.6 * size), (cx, cy, cz)))
    for f in range(zoom):
        t = f / (zoom - 1 if zoom > 1 else 1)
        d = 1.2 * size * (1 - t) + 0.03 * size * t
        cameras.append(((cx + d, cy, cz + 0.5 * d), (cx, cy, cz)))
    passes = 3
    for f in range(fly):
        t = passes * f / fly
        p = int(t) if int(t) < passes else passes - 1
        u = t - p if p % 2 == 0 else 1 - (t - p)
        forward = 1 if p % 2 == 0 else -1
        x = bounds[0] + (bounds[1] - bounds[0]) * (0.1 + 0.8 * u)
        y = bounds[2] + (bounds[3] - bounds[2]) * (0.3 + 0.2 * p)
        cameras.append(((x, y, bounds[5] + 0.02 * size), (x + forward * 0.03 * size, y, cz)))
    return cameras


rows = []
path_start = time.perf_counter()
camera = view.GetActiveCamera()
for index, (position, focal) in enumerate(camera_path(args.frames)):
    camera.SetPosition(position)
    camera.SetFocalPoint(focal)
    camera.SetViewUp(0, 0, 1)
    frame_start = time.perf_counter()
    simple.Render(view)
    seconds = time.perf_counter() - frame_start
    if str(index) in args.shots.split(","):
        simple.SaveScreenshot(os.path.join(temp, f"frame{index:04d}.png"), view, ImageResolution=SIZE)
    display.UpdatePropertyInformation()
    rss, anon = memory_mb()
    row = {"frame": index, "seconds": seconds, "rss": rss, "anon": anon,
           "resident": display.GetPropertyValue("ResidentMB"),
           "pending": int(display.GetPropertyValue("LoadsPending")),
           "drawn": int(display.GetPropertyValue("RegionsDrawn")),
           "substituted": int(display.GetPropertyValue("RegionsSubstituted")),
           "triangles": int(display.GetPropertyValue("TrianglesDrawn")),
           "error": display.GetPropertyValue("LastError")}
    if index >= 100 and index % 10 == 9:
        row["trimmed"] = trimmed_anon_mb()
    rows.append(row)
    if args.explore or index % 100 == 0:
        print(f"frame {index}: {1000 * seconds:.0f} ms, resident {row['resident']:.2f} MB, RSS {rss:.0f} MB "
              f"(anon {anon:.0f}), {row['drawn']} regions ({row['substituted']} substituted), "
              f"{row['triangles']} triangles, pending {row['pending']}", flush=True)
path_seconds = time.perf_counter() - path_start
simple.Delete(display)
simple.Delete(view)


def tables_picture(wait_ms, properties):
    """Coloured by each of `properties` in turn, at a coarse tolerance from the reset camera in
    a new view (its own GPU tables): while interacting (wait_ms 0) rendered until nothing is
    pending, the hash, normal and property tables (9 MB each here) copied a few slabs a frame
    (the third property's table over the first's texture); else one still render that copies
    them whole. Returns (image of the last property, frames rendered)."""
    fresh = simple.CreateRenderView()
    fresh.ViewSize = SIZE
    fresh.OrientationAxesVisibility = 0
    shown = simple.Show(reader, fresh)
    shown.MemoryBudgetMB = budget
    shown.TargetFrameRate = 0
    shown.PixelTolerance = 16
    shown.WaitForDetailMs = wait_ms
    fresh.ResetCamera(False)
    frames = 0
    for name in properties:
        simple.ColorBy(shown, ("CELLS", name))
        while True:
            simple.Render(fresh)
            frames += 1
            shown.UpdatePropertyInformation()
            if wait_ms or not shown.GetPropertyValue("LoadsPending") or frames == 500:
                break
    image = rt.capture_rgb(fresh, os.path.join(temp, f"tables-wait{wait_ms}.png"), *SIZE)
    simple.Delete(shown)
    simple.Delete(fresh)
    return image, frames


staged, staged_frames = tables_picture(0, ["PORO", "NTG", "PERMX"])
whole, _ = tables_picture(60000, ["PERMX"])
staged_differ = int(np.count_nonzero(np.any(staged != whole, axis=2)))
print(f"tables copied while interacting: all loaded after {staged_frames} frames; {staged_differ} pixels differ "
      "from a still render's")
simple.Delete(reader)

resident = [r["resident"] for r in rows]
full = [r["resident"] >= 0.75 * budget for r in rows]
first_full = full.index(True) if True in full else len(rows)
full_share = sum(full[first_full:]) / max(1, len(rows) - first_full)
substituted_share = sum(1 for r in rows if r["substituted"] > 0) / len(rows)
changes_when_full = sum(1 for a, b in zip(resident[first_full:], resident[first_full + 1:]) if a != b)
evicted_at_least = sum(a - b for a, b in zip(resident, resident[1:]) if b < a)
late = rows[2 * len(rows) // 3:]
late_pending = sum(r["pending"] for r in late)
times = sorted(r["seconds"] for r in rows)
at100 = rows[min(100, len(rows) - 1)]


def live_heap(first, last):
    """Medians over frames first..last of the sampled live heap and of ResidentMB there."""
    sampled = [r for r in rows[first:last + 1] if "trimmed" in r]
    heap = sorted(r["trimmed"] for r in sampled)
    resident_there = sorted(r["resident"] for r in sampled)
    return heap[len(heap) // 2], resident_there[len(resident_there) // 2]


# Live heap growth that the resident meshes (draw buffers and, under llvmpipe, their GL copies
# in this process's heap) do not account for: over the path, and within the flight.
n = len(rows)
start_heap, start_resident = live_heap(100, 199)
fly_heap, fly_resident = live_heap(int(0.7 * n), int(0.8 * n) - 1)
end_heap, end_resident = live_heap(n - 100, n - 1)
path_growth = (end_heap - start_heap) - (end_resident - start_resident)
fly_growth = (end_heap - fly_heap) - (end_resident - fly_resident)
print(f"model ready in {prepared:.1f} s; {len(rows)} frames in {path_seconds:.1f} s "
      f"(median {1000 * times[len(times) // 2]:.0f} ms, slowest {1000 * times[-1]:.0f} ms)")
print(f"budget {budget} MB (+ {OVERHEAD_MB} MB): roots {roots_mb:.2f} MB; resident at most {max(resident):.2f} MB, "
      f"at 75% of the budget or more from frame {first_full} and on {100 * full_share:.0f}% of the frames after; "
      f"ancestors substituted on {100 * substituted_share:.0f}% of the frames; the resident set changed on "
      f"{changes_when_full} frames once full; net decreases {evicted_at_least:.1f} MB; "
      f"loads pending on {late_pending} of the last {len(late)} frames")
print(f"RSS at most {max(r['rss'] for r in rows):.0f} MB (RssAnon {max(r['anon'] for r in rows):.0f} MB); VmRSS "
      f"at frame 100 {at100['rss']:.0f} MB, at the last {rows[-1]['rss']:.0f} MB; RssAnon {at100['anon']:.0f} and "
      f"{rows[-1]['anon']:.0f} MB; live heap (medians) {start_heap:.0f} MB over frames 100-199, {fly_heap:.0f} MB "
      f"over the first pass of the flight, {end_heap:.0f} MB over the last 100 frames (resident {start_resident:.0f}, "
      f"{fly_resident:.0f}, {end_resident:.0f} MB): growth beyond the resident meshes {path_growth:.1f} MB over the "
      f"path (limit {LEAK_LIMIT_MB} MB), {fly_growth:.1f} MB within the flight (limit {FLY_LEAK_LIMIT_MB} MB)")

failures = []
over = [r for r in rows if r["resident"] > budget + OVERHEAD_MB]
if over:
    failures.append(f"{len(over)} frames over the budget + {OVERHEAD_MB} MB, first frame {over[0]['frame']}: "
                    f"{over[0]['resident']:.3f} MB")
if not 0 < roots_mb < budget / 2:
    failures.append(f"the roots hold {roots_mb:.2f} MB; expected more than 0 and less than half the budget")
if first_full > 100 or full_share < 0.9:
    failures.append(f"resident memory at 75% of the budget or more from frame {first_full} and on "
                    f"{100 * full_share:.0f}% of the frames after: the path does not press the budget")
if substituted_share < 0.5:
    failures.append(f"ancestors substituted on only {100 * substituted_share:.0f}% of the frames")
if changes_when_full < 30:
    failures.append(f"the resident set changed on only {changes_when_full} frames once full")
if evicted_at_least < budget / 8:
    failures.append(f"net decreases of resident memory add up to {evicted_at_least:.1f} MB < {budget / 8} MB")
if late_pending == 0:
    failures.append("no loads pending in the last third of the path")
if staged_differ or staged_frames == 500:
    failures.append(f"tables copied a slab a frame: {staged_differ} pixels differ from a still render's after "
                    f"{staged_frames} frames")
errors = [r for r in rows if r["error"]]
if errors:
    failures.append(f"LastError on frame {errors[0]['frame']}: {errors[0]['error']}")
if path_growth >= LEAK_LIMIT_MB or fly_growth >= FLY_LEAK_LIMIT_MB:
    failures.append(f"live heap grew by {path_growth:.1f} MB beyond the resident meshes over the path (limit "
                    f"{LEAK_LIMIT_MB} MB) and by {fly_growth:.1f} MB within the flight (limit {FLY_LEAK_LIMIT_MB} "
                    "MB): a leak?")
if failures:
    if not args.explore:
        rt.fail("; ".join(failures))
    print("would fail:", "; ".join(failures))
else:
    print("Multiresolution Surface stays within its memory budget")
