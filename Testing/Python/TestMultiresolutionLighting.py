"""Multiresolution Surface lit as ParaView lights its surfaces: the renderer's lights (the
view's light kit, the headlight) and the display's Ambient, Diffuse and Specular.

Reek and Brugge are built with `resmr build` and `resmr add-properties`, then drawn from the
same cameras by stock ParaView (EGRIDReader, Surface, coloured by PORO) and by the
Multiresolution Surface at 0 px, grid lines off, both lit with the same settings. Checks, over
the pixels both cover:
- the light kit on (ParaView's default), the light kit off with a headlight added, a
  material with ambient and specular terms, and a positional spot light at the camera:
  PSNR >= 30 dB against stock;
- switching the light kit for the headlight changes our image as it changes stock's (the
  mean brightness moves the same way, by more than 5 levels);
- unlit (Ambient 1, Diffuse 0) still gives the lookup table's colours (PSNR >= 40 dB);
- a solid colour with ambient, diffuse and specular terms: PSNR >= 30 dB.
Images of failures are left in the temporary folder."""
import os

import numpy as np
from paraview import simple

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
temp = os.path.join(args.temp, "lighting")
os.makedirs(temp, exist_ok=True)
WIDTH, HEIGHT = 640, 480

MODELS = [
    ("reek", os.path.join(args.data, "reek/res2df_sim/eclipse/model/2_R001_REEK-0.EGRID")),
    ("brugge", os.path.join(args.data, "brugge/Real0/BRUGGE_0000.EGRID")),
]
CAMERAS = [("above", [0.3, -0.5, 0.8], 1.0), ("side", [1.0, -0.3, 0.25], 1.3)]
# (name, light kit, an added light's coordinates and type or None, Ambient, Diffuse, Specular)
LIGHTINGS = [
    ("kit", 1, None, 0.0, 1.0, 0.0),
    ("headlight", 0, ("Headlight", "Directional"), 0.0, 1.0, 0.0),
    ("kit-shiny", 1, None, 0.2, 0.8, 0.5),
    ("spot", 0, ("Camera", "Positional"), 0.1, 0.9, 0.3),
    ("unlit", 1, None, 1.0, 0.0, 0.0),
    ("solid", 1, None, 0.2, 0.8, 0.5),
]


def psnr(a, b):
    mse = float(np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2))
    return float("inf") if mse == 0 else 10 * np.log10(255.0 ** 2 / mse)


def set_lighting(view, displays, kit, added, ambient, diffuse, specular):
    view.UseLight = kit
    for light in list(view.AdditionalLights):
        simple.RemoveLight(light)
    if added:
        light = simple.AddLight(view=view)
        light.Coords, light.Type = added
        if added[1] == "Positional":
            light.Position = [0.0, 0.0, 0.0]  # at the camera, a cone along its view
            light.FocalPoint = [0.0, 0.0, -1.0]
            light.ConeAngle = 20.0
    for display in displays:
        display.Ambient = ambient
        display.Diffuse = diffuse
        display.Specular = specular


view = rt.image_view(WIDTH, HEIGHT)
failures = []
for name, grid_path in MODELS:
    resmr_path = os.path.join(temp, name + ".resmr")
    if not os.path.exists(resmr_path):
        rt.run_resmr("build", grid_path, "-o", resmr_path, "--quiet")
    if not os.path.exists(resmr_path + "p"):
        rt.run_resmr("add-properties", resmr_path, grid_path)
    stock_reader = simple.EGRIDReader(FileName=grid_path, ApplyMapAxes=0)
    stock_reader.UpdatePipeline()
    bounds = stock_reader.GetDataInformation().GetBounds()
    stock = simple.Show(stock_reader, view)
    stock.SetRepresentationType("Surface")
    simple.ColorBy(stock, ("CELLS", "PORO"))
    stock.RescaleTransferFunctionToDataRange(False, False)
    reader = simple.OpenDataFile(resmr_path)
    reader.ApplyMapAxes = 0
    ours = simple.Show(reader, view)
    ours.GridLines = 0
    ours.PixelTolerance = 0
    ours.WaitForDetailMs = 120000
    simple.ColorBy(ours, ("CELLS", "PORO"))
    means = {}
    for lighting, kit, added, ambient, diffuse, specular in LIGHTINGS:
        set_lighting(view, (stock, ours), kit, added, ambient, diffuse, specular)
        if lighting == "solid":
            for display in (stock, ours):
                simple.ColorBy(display, None)
                display.AmbientColor = display.DiffuseColor = [0.8, 0.7, 0.5]
        for camera, direction, zoom in CAMERAS:
            tag = f"{name}-{lighting}-{camera}"
            simple.Hide(reader, view)
            simple.Show(stock_reader, view)
            rt.place_camera(view, bounds, 1.0, direction, zoom)
            expected = rt.capture_rgb(view, os.path.join(temp, tag + "-stock.png"), WIDTH, HEIGHT)
            simple.Hide(stock_reader, view)
            simple.Show(reader, view)
            simple.Render(view)
            got = rt.capture_rgb(view, os.path.join(temp, tag + "-ours.png"), WIDTH, HEIGHT)
            both = (expected.sum(axis=2) > 0) & (got.sum(axis=2) > 0)
            if both.sum() < 0.05 * WIDTH * HEIGHT:
                failures.append(f"{tag}: the model covers too few pixels ({int(both.sum())})")
                continue
            quality = psnr(expected[both], got[both])
            means[(lighting, camera)] = (float(expected[both].mean()), float(got[both].mean()))
            print(f"{tag}: PSNR {quality:.1f} dB over {int(both.sum())} pixels; mean level stock "
                  f"{means[(lighting, camera)][0]:.1f}, ours {means[(lighting, camera)][1]:.1f}")
            required = 40.0 if lighting == "unlit" else 30.0
            if quality < required:
                failures.append(f"{tag}: PSNR {quality:.1f} dB < {required:g}")
    for camera, _, _ in CAMERAS:
        kit, head = means.get(("kit", camera)), means.get(("headlight", camera))
        if kit and head:
            stock_move, our_move = head[0] - kit[0], head[1] - kit[1]
            print(f"{name} {camera}: light kit to headlight moves stock's mean by {stock_move:+.1f}, ours by "
                  f"{our_move:+.1f}")
            if abs(stock_move) > 5 and (np.sign(stock_move) != np.sign(our_move) or abs(our_move) < 5):
                failures.append(f"{name} {camera}: the lights change stock's image by {stock_move:+.1f} and ours "
                                f"by {our_move:+.1f}")
    for proxy in (reader, stock_reader):
        simple.Delete(proxy)

if failures:
    rt.fail("; ".join(failures))
print("PASS")
