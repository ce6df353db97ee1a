"""The main job's second half: opens a .resmr with the Multiresolution Surface representation
(paper Sec. 5, 6.2, 6.3), coloured by PORO with the original grid lines, the controller holding
10 frames per second.

- In the ParaView GUI (`paraview --script=scripts/demo_view.py`, settings from the environment:
  RESMR_DEMO_FILE) it sets up the view and leaves the flying to the user.
- In pvpython (`pvpython scripts/demo_view.py PLUGIN FILE.resmr OUTPUT_DIR`) it flies a scripted
  path (orbit, zoom to close inspection, low flight along the faults) and writes every 25th
  frame as a PNG and the frame times, tolerances and memory to OUTPUT_DIR/flythrough.txt,
  then cuts the model open with Multiresolution Extract Subset (the cells with I up to three
  fifths of NI and K from the second layer down, exact at 0 px) and shows the water saturation
  of the last report step on the cut: OUTPUT_DIR/*_range_swat.png; then keeps, with
  Multiresolution Threshold, only the cells the water has swept at the last step (SWAT of 0.5
  and more), the water front: OUTPUT_DIR/*_waterfront.png.
"""
import math
import os
import sys
import time

from paraview import simple

TARGET_FPS = 10
VERTICAL_EXAGGERATION = 5
FRAMES = 240


def open_model(path, view):
    reader = simple.OpenDataFile(path)
    display = simple.Show(reader, view)
    display.SetRepresentationType("Multiresolution Surface")
    display.TargetFrameRate = TARGET_FPS
    display.GridLines = 1
    display.Scale = [1, 1, VERTICAL_EXAGGERATION]
    simple.ColorBy(display, ("CELLS", "PORO"))
    simple.GetColorTransferFunction("PORO").ApplyPreset("Viridis (matplotlib)", True)
    display.RescaleTransferFunctionToDataRange(False, True)
    display.SetScalarBarVisibility(view, True)
    return reader, display


def camera_path(bounds, frames):
    """(position, focal point) a frame: a half orbit, a zoom to a few cells across, then a low
    flight across the field (the generator's faults cut it every few hundred metres)."""
    cx, cy = (bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2
    cz = VERTICAL_EXAGGERATION * (bounds[4] + bounds[5]) / 2
    top = VERTICAL_EXAGGERATION * bounds[5]
    size = max(bounds[1] - bounds[0], bounds[3] - bounds[2])
    orbit, zoom = int(frames * 0.4), int(frames * 0.3)
    cameras = []
    for f in range(orbit):
        a = math.pi * (1.25 + f / orbit)
        cameras.append(((cx + 0.9 * size * math.cos(a), cy + 0.9 * size * math.sin(a), cz + 0.5 * size), (cx, cy, cz)))
    start = cameras[-1][0]
    for f in range(zoom):
        t = (f + 1) / zoom
        near = (cx - 0.03 * size, cy - 0.03 * size, top + 0.02 * size)
        cameras.append((tuple(start[i] + (near[i] - start[i]) * t for i in range(3)), (cx, cy, cz)))
    fly = frames - orbit - zoom
    for f in range(fly):
        t = f / max(fly - 1, 1)
        x = cx - 0.03 * size + 0.45 * size * t
        cameras.append(((x, cy - 0.03 * size, top + 0.02 * size), (x + 0.1 * size, cy + 0.05 * size, cz)))
    return cameras


def gui():
    view = simple.GetActiveViewOrCreate("RenderView")
    path = os.environ["RESMR_DEMO_FILE"]
    reader, _ = open_model(path, view)
    position, focal = camera_path(reader.GetDataInformation().GetBounds(), FRAMES)[0]
    camera = view.GetActiveCamera()
    camera.SetFocalPoint(focal)
    camera.SetPosition(position)
    camera.SetViewUp(0, 0, 1)
    view.ResetCamera(False)
    simple.Render(view)
    if os.environ.get("RESMR_DEMO_SCREENSHOT"):  # for checking the GUI set-up headless
        simple.SaveScreenshot(os.environ["RESMR_DEMO_SCREENSHOT"], view)


def flythrough(plugin, path, output):
    simple.LoadPlugin(plugin, remote=False, ns=vars(simple))
    os.makedirs(output, exist_ok=True)
    view = simple.CreateView("RenderView")
    view.ViewSize = [1280, 720]
    view.OrientationAxesVisibility = 0
    start = time.perf_counter()
    reader, display = open_model(path, view)
    view.ResetCamera(False)
    simple.Render(view)
    first_image = time.perf_counter() - start
    display.UpdatePropertyInformation()
    error = display.GetPropertyValue("LastError")
    if error:
        sys.exit(f"demo: {path}: {error}")
    bounds = reader.GetDataInformation().GetBounds()
    camera = view.GetActiveCamera()
    camera.SetViewUp(0, 0, 1)
    lines = ["frame ms tolerance_px triangles resident_mb"]
    times = []
    prefix = os.path.splitext(os.path.basename(path))[0]
    for frame, (position, focal) in enumerate(camera_path(bounds, FRAMES)):
        camera.SetPosition(position)
        camera.SetFocalPoint(focal)
        camera.SetViewUp(0, 0, 1)
        view.CameraParallelProjection = 0
        tick = time.perf_counter()
        simple.Render(view)
        times.append(time.perf_counter() - tick)
        display.UpdatePropertyInformation()
        lines.append(f"{frame} {1000 * times[-1]:.1f} {display.GetPropertyValue('CurrentTolerance'):.2f} "
                     f"{display.GetPropertyValue('TrianglesDrawn')} {display.GetPropertyValue('ResidentMB'):.1f}")
        if frame % 25 == 0 or frame == FRAMES - 1:
            simple.SaveScreenshot(os.path.join(output, f"{prefix}_flythrough_{frame:03d}.png"), view,
                                  ImageResolution=[1280, 720])
    ordered = sorted(times)
    p50, p99 = ordered[len(ordered) // 2], ordered[min(len(ordered) - 1, int(0.99 * len(ordered)))]
    summary = (f"demo: {path}: first image {first_image:.2f} s; {FRAMES} frames, p50 {1000 * p50:.0f} ms, "
               f"p99 {1000 * p99:.0f} ms (target {1000 / TARGET_FPS:.0f} ms); frames and screenshots in {output}")
    with open(os.path.join(output, f"{prefix}_flythrough.txt"), "w") as out:
        out.write("# " + summary + "\n" + "\n".join(lines) + "\n")
    print(summary)
    range_view(reader, display, view, os.path.join(output, f"{prefix}_range_swat.png"))
    water_front(reader, view, os.path.join(output, f"{prefix}_waterfront.png"))


def range_view(reader, display, view, screenshot):
    """The model cut open along I and below its first layer, coloured by SWAT at the last step."""
    subset = simple.MultiresolutionExtractSubset(Input=reader)
    subset.UpdatePipelineInformation()
    voi_range = list(subset.GetPropertyValue("VOIRange"))
    ni, nj, nk = voi_range[1], voi_range[5], voi_range[9]
    subset.VOI = [1, 3 * ni // 5, 1, nj, 2, nk]
    simple.Hide(reader, view)
    cut = simple.Show(subset, view)
    cut.Scale = [1, 1, VERTICAL_EXAGGERATION]
    cut.GridLines = 1
    cut.PixelTolerance = 1
    cut.WaitForDetailMs = 120000
    scene = simple.GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    times = list(reader.TimestepValues) if reader.TimestepValues else [0]
    scene.AnimationTime = times[-1]
    simple.ColorBy(cut, ("CELLS", "SWAT"))
    simple.GetColorTransferFunction("SWAT").ApplyPreset("Blue Orange (divergent)", True)
    simple.GetColorTransferFunction("SWAT").RescaleTransferFunction(0.0, 1.0)
    cut.SetScalarBarVisibility(view, True)
    bounds = reader.GetDataInformation().GetBounds()
    cx, cy = (bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2
    cz = VERTICAL_EXAGGERATION * (bounds[4] + bounds[5]) / 2
    size = max(bounds[1] - bounds[0], bounds[3] - bounds[2])
    camera = view.GetActiveCamera()
    # Facing the cut at I = 3/5 from outside the box, a little above it.
    cut_x = bounds[0] + 0.6 * (bounds[1] - bounds[0])
    camera.SetFocalPoint(cut_x - 0.1 * size, cy, cz)
    camera.SetPosition(cut_x + 0.55 * size, cy - 0.45 * size, cz + 0.25 * size)
    camera.SetViewUp(0, 0, 1)
    simple.Render(view)
    simple.SaveScreenshot(screenshot, view, ImageResolution=[1280, 720])
    print(f"demo: the model cut open at I = {3 * ni // 5} and below K = 1, SWAT at day {times[-1]:g}: {screenshot}")


def water_front(reader, view, screenshot):
    """The cells swept by water at the last step (SWAT >= 0.5), coloured by SWAT: the front."""
    for source in simple.GetSources().values():
        simple.Hide(source, view)
    swept = simple.MultiresolutionThreshold(Input=reader)
    swept.Scalars = ["CELLS", "SWAT"]
    swept.LowerThreshold, swept.UpperThreshold = 0.5, 1.0
    front = simple.Show(swept, view)
    front.Scale = [1, 1, VERTICAL_EXAGGERATION]
    front.GridLines = 1
    front.PixelTolerance = 1
    front.WaitForDetailMs = 120000
    simple.ColorBy(front, ("CELLS", "SWAT"))
    front.SetScalarBarVisibility(view, True)
    bounds = reader.GetDataInformation().GetBounds()
    cx, cy = (bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2
    cz = VERTICAL_EXAGGERATION * (bounds[4] + bounds[5]) / 2
    size = max(bounds[1] - bounds[0], bounds[3] - bounds[2])
    camera = view.GetActiveCamera()
    camera.SetFocalPoint(cx, cy, cz)
    camera.SetPosition(cx + 0.45 * size, cy - 1.0 * size, cz + 0.75 * size)
    camera.SetViewUp(0, 0, 1)
    simple.Render(view)
    simple.SaveScreenshot(screenshot, view, ImageResolution=[1280, 720])
    print(f"demo: the cells with SWAT from 0.5 to 1 at the last step (the water front): {screenshot}")


if len(sys.argv) >= 4:
    flythrough(*sys.argv[1:4])
else:
    gui()
