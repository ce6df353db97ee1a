"""Moving frames at a reduced resolution: with a target frame rate the surface cannot hold
(1000 FPS here, so every frame is slow), a moving camera first lowers the render scale to
Moving Resolution Floor, and the tolerance stays; the still frame after it is drawn in full.

On the faulted synthetic model, with a sphere cutting through the surface (the stretched
surface must hide it and be hidden by it through the depth it writes):
- the readout: CurrentRenderScale 1 on the first frame, the floor (0.5) on moving frames,
  1 again on the still frame and on a screenshot; 1 throughout with the floor at 1, without a
  target frame rate, and when still renders wait for detail (WaitForDetailMs);
- the moving frame, as drawn (read back without rendering again), against the still frame of
  the same camera and tolerance: the surface's and the sphere's pixels agree outside a 2-pixel
  band around their outlines (at most 0.5% of pixels differ), the lit surface's colours inside
  agree within 24 levels a channel on >= 97% of its pixels, and with grid lines on, lines
  cover between half and twice the share of the surface they cover in the still frame;
- the tolerance is not coarsened while the scale can still fall: the frame the scale fell on
  keeps the tolerance of the frame before.
Images are left in the temporary folder."""
import os

import numpy as np
from paraview import simple

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
temp = os.path.join(args.temp, "moving")
os.makedirs(temp, exist_ok=True)
WIDTH, HEIGHT = 640, 480
failures = []


def check(condition, message):
    print(("ok   " if condition else "FAIL ") + message)
    if not condition:
        failures.append(message)


drawn_pixels = rt.drawn_pixels


def save(pixels, name):
    rt.save_png(pixels, os.path.join(temp, name))


def scale_of(display):
    display.UpdatePropertyInformation()
    return display.GetPropertyValue("CurrentRenderScale")


def tolerance_of(display):
    display.UpdatePropertyInformation()
    return display.GetPropertyValue("CurrentTolerance")


def orbit(view, display, frames, degrees=2.0):
    """Renders `frames` frames, the camera turning between them: the scales they were drawn at."""
    scales = []
    for _ in range(frames):
        view.GetActiveCamera().Azimuth(degrees)
        simple.Render(view)
        scales.append(scale_of(display))
    return scales


def masks(pixels):
    """(sphere, surface): the sphere is pure red (unlit), the surface grey, the background black."""
    red = (pixels[..., 0] > 150) & (pixels[..., 1] < 40) & (pixels[..., 2] < 40)
    covered = pixels.sum(axis=2) > 30
    return red, covered & ~red


def band(mask, width):
    """Pixels within `width` of the mask's outline."""
    return mask & ~rt.erode(mask, width, corners=True) | ~mask & ~rt.erode(~mask, width, corners=True)


model = rt.faulted_synthetic(temp)
resmr_path = os.path.join(temp, "faulted.resmr")
if not os.path.exists(resmr_path):
    rt.run_resmr("build", model, "-o", resmr_path, "--quiet")

view = rt.image_view(WIDTH, HEIGHT)

reader = simple.OpenDataFile(resmr_path)
display = simple.Show(reader, view)
display.PaintBy = "Solid Color"
display.AmbientColor = [0.8, 0.8, 0.8]
display.DiffuseColor = [0.8, 0.8, 0.8]
display.PixelTolerance = 0
bounds = reader.GetDataInformation().GetBounds()
center = [(bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2, (bounds[4] + bounds[5]) / 2]
sphere = simple.Sphere(Center=center, Radius=0.25 * (bounds[1] - bounds[0]), ThetaResolution=64,
                       PhiResolution=64)
sphere_display = simple.Show(sphere, view)
sphere_display.AmbientColor = [1.0, 0.0, 0.0]
sphere_display.DiffuseColor = [1.0, 0.0, 0.0]
rt.unlit(sphere_display)
simple.Render(view)  # the first render places the camera; ours comes after it
view.ResetCamera(False)
camera = view.GetActiveCamera()
camera.Elevation(35)
camera.Azimuth(20)
camera.Zoom(2.2)

# Detail first, so that the frames below are all fill: the still frame waits for every mesh.
display.WaitForDetailMs = 60000
simple.Render(view)
display.WaitForDetailMs = 0

def moving_and_still(tag):
    """A moving frame at the floor, as drawn, and the still frame of its camera and tolerance."""
    display.TargetFrameRate = 1000
    display.MovingResolutionFloor = 0.5
    simple.Render(view)
    check(scale_of(display) == 1, f"{tag}: a still frame is drawn in full (scale {scale_of(display)})")
    first = orbit(view, display, 1)
    tolerance_first = tolerance_of(display)
    second = orbit(view, display, 1)
    check(first == [1] and second == [0.5],
          f"{tag}: the first moving frame lowers the scale to the floor: {first + second}")
    check(tolerance_of(display) <= tolerance_first,
          f"{tag}: the tolerance waits for the scale (it may refine to the estimated-error floor, never coarsen): "
          f"{tolerance_first} px, then {tolerance_of(display)} px")
    moving = drawn_pixels(view)
    display.PixelTolerance = tolerance_of(display)
    display.TargetFrameRate = 0
    display.WaitForDetailMs = 60000
    simple.Render(view)
    still_scale = scale_of(display)
    still = drawn_pixels(view)
    save(moving, f"{tag}-moving.png")
    save(still, f"{tag}-still.png")
    check(still_scale == 1, f"{tag}: the still frame of the same camera is drawn in full (scale {still_scale})")
    display.PixelTolerance = 0
    display.WaitForDetailMs = 0
    return moving, still


# The lit surface without grid lines: outlines, depth against the sphere, colours.
display.GridLines = 0
moving, still = moving_and_still("lit")
sphere_moving, surface_moving = masks(moving)
sphere_still, surface_still = masks(still)
check(surface_still.sum() > 0.2 * WIDTH * HEIGHT and sphere_still.sum() > 0.01 * WIDTH * HEIGHT
      and (sphere_still & rt.erode(surface_still | sphere_still, 3)).sum() > 0,
      f"the view holds the surface ({int(surface_still.sum())} px) and the sphere "
      f"({int(sphere_still.sum())} px) against it")
for name, a, b in (("surface", surface_moving, surface_still), ("sphere", sphere_moving, sphere_still)):
    outside = ~band(b, 2)
    differ = float(np.mean((a != b) & outside))
    check(differ <= 0.005, f"{name} pixels of the moving frame agree with the still one's outside a 2-pixel "
          f"band: {100 * differ:.3f}% differ")
inner = rt.erode(surface_still, 3, corners=True) & rt.erode(surface_moving, 3, corners=True)
close = np.max(np.abs(moving - still), axis=2) <= 24
share = float(np.mean(close[inner])) if inner.any() else 0.0
check(share >= 0.97, f"surface colours agree within 24 levels on {100 * share:.2f}% of {int(inner.sum())} pixels")

# Grid lines keep their width on the view: about as many line pixels in either frame.
display.GridLines = 1
moving, still = moving_and_still("lines")
_, surface_moving = masks(moving)
_, surface_still = masks(still)
inner = rt.erode(surface_still, 3, corners=True) & rt.erode(surface_moving, 3, corners=True)
level = np.median(still.sum(axis=2)[inner])
lines_moving = float(np.mean(moving.sum(axis=2)[inner] < 0.6 * level))
lines_still = float(np.mean(still.sum(axis=2)[inner] < 0.6 * level))
check(lines_still > 0.05 and 0.5 <= lines_moving / lines_still <= 2.0,
      f"grid lines cover {100 * lines_moving:.1f}% of the moving frame's surface, {100 * lines_still:.1f}% of "
      f"the still one's")

# A moving frame drawn reduced asks for a still frame, and a screenshot renders the same
# camera again: in full.
display.TargetFrameRate = 1000
orbit(view, display, 3)
check(scale_of(display) == 0.5, f"moving frames again at the floor (scale {scale_of(display)})")
simple.Render(view)
check(scale_of(display) == 1, f"the next render of the same camera is in full (scale {scale_of(display)})")
orbit(view, display, 3)
simple.SaveScreenshot(os.path.join(temp, "screenshot.png"), view, ImageResolution=[WIDTH, HEIGHT],
                      TransparentBackground=0)
check(scale_of(display) == 1, f"a screenshot is drawn in full (scale {scale_of(display)})")

# Full resolution throughout: the floor at 1, no target frame rate, or waiting for detail.
for setting, value in (("MovingResolutionFloor", 1.0), ("TargetFrameRate", 0.0), ("WaitForDetailMs", 60000)):
    display.MovingResolutionFloor = 0.5
    display.TargetFrameRate = 1000
    display.WaitForDetailMs = 0
    display.SetPropertyWithName(setting, value)
    simple.Render(view)
    scales = orbit(view, display, 4)
    check(all(s == 1 for s in scales), f"{setting} = {value}: moving frames in full, scales {scales}")

if failures:
    rt.fail("; ".join(failures))
print("moving resolution: all checks passed")
simple.Delete(display)
simple.Delete(view)
