"""Detail traded last, and frames that can be drawn again: with a target frame rate the
surface cannot hold (1000 FPS, so every frame is slow) and full resolution kept while moving
(Moving Resolution Floor 1, so the controller can only coarsen the geometry), on the faulted
synthetic model:
- the quality floor: over 40 moving frames the tolerance rises to Maximum Pixel Tolerance
  (16 px here, with no floor on the estimated error) and never past it; raised to 65536, the
  same frames go past it;
- the floor on the estimated error: with Maximum Pixel Tolerance at 65536 and Maximum
  Estimated Error at a quarter of the estimate those unbounded frames reached, the same slow
  frames keep their estimate (CurrentEstimatedError) within it, all but the frames that step
  back under it, and their tolerance below the unbounded frames';
- a still frame (the camera stopped) is drawn at the user's Pixel Tolerance whatever the
  controller chose, and the controller resumes where it was on the next moving frame;
- reproducible: a moving frame drawn whole (no region standing in for one still loading) at
  the controller's tolerance T is drawn again, same camera, with Pixel Tolerance = T and no
  target frame rate: the same triangles and regions;
- Pixel Tolerance accepts any tolerance the controller can choose (up to 65536 px);
- the readout (CurrentFrameMoving) says which frames were moving and which still."""
import os

from paraview import simple

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
temp = os.path.join(args.temp, "quality-floor")
os.makedirs(temp, exist_ok=True)
failures = []


def check(condition, message):
    print(("ok   " if condition else "FAIL ") + message)
    if not condition:
        failures.append(message)


def readout(display):
    display.UpdatePropertyInformation()
    return {name: display.GetPropertyValue(name) for name in
            ("CurrentTolerance", "CurrentEstimatedError", "TrianglesDrawn", "RegionsDrawn", "RegionsSubstituted", "LoadsPending",
             "CurrentFrameMoving")}


def moving_frames(view, display, frames, degrees=1.5):
    """Renders `frames` frames, the camera turning between them: each frame's readout."""
    seen = []
    for _ in range(frames):
        view.GetActiveCamera().Azimuth(degrees)
        simple.Render(view)
        seen.append(readout(display))
    return seen


model = rt.faulted_synthetic(temp)
resmr_path = os.path.join(temp, "faulted.resmr")
if not os.path.exists(resmr_path):
    rt.run_resmr("build", model, "-o", resmr_path, "--quiet")

view = rt.image_view(640, 480)
reader = simple.OpenDataFile(resmr_path)
display = simple.Show(reader, view)
display.PaintBy = "Cell Id"
display.PixelTolerance = 1
simple.Render(view)
view.ResetCamera(False)
camera = view.GetActiveCamera()
camera.Elevation(35)
camera.Zoom(1.5)
display.WaitForDetailMs = 60000  # every mesh resident before the frames below
display.PixelTolerance = 0
simple.Render(view)
display.PixelTolerance = 1
display.WaitForDetailMs = 0

display.MovingResolutionFloor = 1.0
display.MaximumPixelTolerance = 16
display.MaximumEstimatedError = 0
display.TargetFrameRate = 1000
frames = moving_frames(view, display, 40)
tolerances = [f["CurrentTolerance"] for f in frames]
check(max(tolerances) <= 16, f"moving frames stay within the 16 px floor: up to {max(tolerances):g} px")
check(tolerances[-1] == 16, f"slow frames push the tolerance to the floor: last {tolerances[-1]:g} px")
check(all(f["CurrentFrameMoving"] == 1 for f in frames), "the readout calls every moving frame moving")

simple.Render(view)  # the same camera: a still frame
still = readout(display)
check(still["CurrentTolerance"] == 1, f"a still frame uses the user's 1 px: {still['CurrentTolerance']:g} px")
check(still["CurrentFrameMoving"] == 0, "the readout calls the still frame still")
resumed = moving_frames(view, display, 1)[0]["CurrentTolerance"]
check(resumed == 16, f"the next moving frame resumes at the controller's 16 px: {resumed:g} px")

display.MaximumPixelTolerance = 65536
unbounded = moving_frames(view, display, 20)
beyond = [f["CurrentTolerance"] for f in unbounded]
check(max(beyond) > 16, f"with the floor at 65536 the same frames coarsen past 16 px: up to {max(beyond):g} px")
reached = max(f["CurrentEstimatedError"] for f in unbounded)
check(reached > 0, f"coarse frames have an estimated error: up to {reached:.2f} px")

# The floor on the estimated error, the bound's lifted: the same slow frames, from the
# controller's tolerance where the unbounded frames left it.
floor = reached / 4
display.MaximumEstimatedError = floor
steered = moving_frames(view, display, 40)
whole_frames = [f for f in steered[10:] if f["RegionsSubstituted"] == 0]
within = [f for f in whole_frames if f["CurrentEstimatedError"] <= floor * 1.0001]
check(len(whole_frames) >= 10 and len(within) >= 0.8 * len(whole_frames),
      f"with Maximum Estimated Error {floor:.2f} px, {len(within)} of the last {len(whole_frames)} whole moving "
      f"frames keep their estimate within it (up to {max(f['CurrentEstimatedError'] for f in steered[10:]):.2f} px)")
check(max(f["CurrentTolerance"] for f in steered[10:]) < max(beyond),
      f"the estimate holds the tolerance back: up to {max(f['CurrentTolerance'] for f in steered[10:]):g} px, "
      f"{max(beyond):g} px without it")
display.MaximumEstimatedError = 0

# Reproducible: a whole moving frame at the controller's tolerance, then the same camera with
# that tolerance typed in. A reachable rate lets the tolerance come down from where the slow
# frames left it, through values no one would type.
display.MaximumPixelTolerance = 65536
display.TargetFrameRate = 30
whole = None
for _ in range(100):
    f = moving_frames(view, display, 1, degrees=0.5)[0]
    if f["RegionsSubstituted"] == 0 and 1 < f["CurrentTolerance"] < 64 and f["RegionsDrawn"] > 2:
        whole = f  # the camera stays where this frame drew it
        break
check(whole is not None, "a moving frame drew every region it selected")
if whole is not None:
    display.TargetFrameRate = 0
    display.PixelTolerance = whole["CurrentTolerance"]
    display.WaitForDetailMs = 60000
    simple.Render(view)
    again = readout(display)
    check(again["CurrentTolerance"] == whole["CurrentTolerance"],
          f"the controller's tolerance {whole['CurrentTolerance']!r} px is accepted as Pixel Tolerance "
          f"({again['CurrentTolerance']!r})")
    check((again["TrianglesDrawn"], again["RegionsDrawn"]) == (whole["TrianglesDrawn"], whole["RegionsDrawn"]),
          f"drawn again at {whole['CurrentTolerance']:g} px: {int(again['TrianglesDrawn'])} triangles in "
          f"{again['RegionsDrawn']} regions, the moving frame {int(whole['TrianglesDrawn'])} in "
          f"{whole['RegionsDrawn']}")

display.PixelTolerance = 65536
simple.Render(view)
check(readout(display)["CurrentTolerance"] == 65536, "Pixel Tolerance accepts 65536 px")

if failures:
    rt.fail("; ".join(failures))
print("quality floor: all checks passed")
simple.Delete(display)
simple.Delete(view)
