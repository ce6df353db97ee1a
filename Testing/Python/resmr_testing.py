"""Shared helpers for the pvpython tests: argument parsing, loading the plugin, reading a
deck through the GRDECLReader proxy, and image comparison against a baseline."""
import argparse
import os
import shutil
import subprocess
import sys

import numpy as np


def arguments():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--data", required=True, help="shared data folder")
    parser.add_argument("--baselines", default="")
    parser.add_argument("--temp", default="/tmp")
    return parser.parse_args()


def gui_model(args, folder):
    """For the GUI tests: the paraview executable, TEMP/folder and a generated faulted model
    with its properties there (120 x 100 x 16, built once); exits 125 (skipped) without a
    paraview executable or an X display."""
    paraview = os.environ.get("PARAVIEW_EXECUTABLE", "")
    if not paraview or not os.path.exists(paraview) or not os.environ.get("DISPLAY"):
        print(f"skipped: paraview {paraview!r}, DISPLAY {os.environ.get('DISPLAY')!r}")
        sys.exit(125)
    resmr = os.environ["RESMR_EXECUTABLE"]
    temp = os.path.join(args.temp, folder)
    os.makedirs(temp, exist_ok=True)
    grid = os.path.join(temp, "faulted.EGRID")
    path = os.path.join(temp, "faulted.resmr")
    if not os.path.exists(path + "p"):
        for command in (["synth", "120", "100", "16", "-o", grid, "--quiet"], ["build", grid, "-o", path, "--quiet"],
                        ["add-properties", path, grid]):
            subprocess.run([resmr, *command], check=True, capture_output=True)
    return paraview, temp, path


def load_plugin(path):
    from paraview import simple
    simple.LoadPlugin(path, remote=False, ns=vars(simple))


def read_grid(path, **properties):
    """Runs GRDECLReader on path and returns (proxy, vtkExplicitStructuredGrid copy)."""
    from paraview import servermanager, simple
    reader = simple.GRDECLReader(FileName=path, **properties)
    reader.UpdatePipeline()
    data = servermanager.Fetch(reader, arg1=None, arg2=None, idx=0)
    return reader, data


def cell_array(grid, name):
    from vtkmodules.util.numpy_support import vtk_to_numpy
    array = grid.GetCellData().GetArray(name)
    if array is None:
        raise AssertionError(f"cell array {name} missing")
    return vtk_to_numpy(array)


def points_and_cells(grid):
    """Points (n, 3) and hexahedron point ids (cells, 8), in VTK order."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    points = vtk_to_numpy(grid.GetPoints().GetData()).astype(np.float64)
    connectivity = vtk_to_numpy(grid.GetCells().GetConnectivityArray())
    return points, connectivity.reshape(-1, 8)


def expect_read_error(reader, name, fragments):
    """Updates `reader` on a bad file: its output must be empty and its LastError must hold
    every fragment (file, keyword, what). Deletes the reader; returns the message."""
    from paraview import servermanager, simple
    reader.UpdatePipeline()
    grid = servermanager.Fetch(reader, arg1=None, arg2=None, idx=0)
    reader.UpdatePropertyInformation()
    text = reader.GetPropertyValue("LastError")
    # An empty vtkExplicitStructuredGrid reports 1 cell from its extent: count real ones.
    if hasattr(grid, "GetCells"):
        cells = grid.GetCells().GetNumberOfCells() if grid.GetCells() else 0
    else:
        cells = grid.GetNumberOfCells()
    if cells != 0 or grid.GetNumberOfPoints() != 0:
        fail(f"{name}: output not empty ({cells} cells, {grid.GetNumberOfPoints()} points)")
    missing = [f for f in fragments if f not in text]
    if missing:
        fail(f"{name}: error message lacks {missing}: {text!r}")
    print(f"{name}: error reported: {text}")
    simple.Delete(reader)
    return text


def place_camera(view, bounds, exaggeration, direction, zoom):
    """Looks at the centre of `bounds` (z scaled by `exaggeration`) from `direction`, z up,
    then dollies by `zoom`. Call after the first Render, which resets the camera."""
    from paraview import simple
    centre = [(bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2,
              exaggeration * (bounds[4] + bounds[5]) / 2]
    size = max(bounds[1] - bounds[0], bounds[3] - bounds[2])
    camera = view.GetActiveCamera()
    camera.SetFocalPoint(centre)
    camera.SetPosition([centre[i] + direction[i] * size for i in range(3)])
    camera.SetViewUp(0, 0, 1)
    view.ResetCamera(False)
    camera.Dolly(zoom)
    simple.Render(view)


def compare_image(render_view, baseline_dir, name, temp_dir, threshold=0.05, max_changed=0.01):
    """Saves the view and compares it to baseline_dir/name. Missing baselines fail the test
    and leave the new image in temp_dir for a person to look at."""
    from paraview import simple
    from paraview.vtk.test import Testing
    os.makedirs(temp_dir, exist_ok=True)
    produced = os.path.join(temp_dir, name)
    simple.SaveScreenshot(produced, render_view, ImageResolution=[800, 600])
    baseline = os.path.join(baseline_dir, name)
    if not os.path.exists(baseline):
        raise AssertionError(f"no baseline {baseline}; new image left at {produced}")
    from vtkmodules.vtkIOImage import vtkPNGReader
    from vtkmodules.vtkImagingCore import vtkImageDifference
    images = []
    for path in (produced, baseline):
        reader = vtkPNGReader()
        reader.SetFileName(path)
        reader.Update()
        images.append(reader.GetOutput())
    difference = vtkImageDifference()
    difference.SetInputData(images[0])
    difference.SetImageData(images[1])
    difference.Update()
    error = difference.GetThresholdedError()
    # vtkImageDifference forgives colour shifts of up to about 100 levels a pixel, so a wrong
    # colour map or property can pass it: also count pixels whose colour moved visibly.
    from vtkmodules.util.numpy_support import vtk_to_numpy
    pixels = [vtk_to_numpy(image.GetPointData().GetScalars()).astype(np.int32)[:, :3] for image in images]
    if pixels[0].shape != pixels[1].shape:
        raise AssertionError(f"{name}: size differs from its baseline; see {produced}")
    moved = float(np.mean(np.max(np.abs(pixels[0] - pixels[1]), axis=1) > 10))
    print(f"{name}: image difference {error:.4f} (threshold {threshold}), "
          f"{100 * moved:.2f}% of pixels changed colour (limit {100 * max_changed:.1f}%)")
    if error > threshold or moved > max_changed:
        raise AssertionError(f"{name} differs from its baseline (difference {error:.4f}, "
                             f"{100 * moved:.2f}% of pixels changed); see {produced}")


def image_view(width, height):
    """A render view for pixel comparisons: black background, no axes, no FXAA."""
    from paraview import simple
    view = simple.CreateRenderView()
    view.ViewSize = [width, height]
    view.OrientationAxesVisibility = 0
    view.Background = [0.0, 0.0, 0.0]
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    view.UseFXAA = 0
    return view


def capture_rgb(view, path, width, height):
    """Saves the view (opaque background) and returns its pixels, (height, width, 3) int64."""
    from paraview import simple
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOImage import vtkPNGReader
    simple.SaveScreenshot(path, view, ImageResolution=[width, height], TransparentBackground=0)
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    pixels = vtk_to_numpy(reader.GetOutput().GetPointData().GetScalars())[:, :3].astype(np.int64)
    return pixels.reshape(height, width, 3)


def drawn_pixels(view):
    """The view's last frame as drawn, without rendering it again: (height, width, 3) int64."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter
    grab = vtkWindowToImageFilter()
    grab.SetInput(view.GetRenderWindow())
    grab.ShouldRerenderOff()
    grab.ReadFrontBufferOff()
    grab.Update()
    image = grab.GetOutput()
    width, height, _ = image.GetDimensions()
    pixels = vtk_to_numpy(image.GetPointData().GetScalars())[:, :3].astype(np.int64)
    return pixels.reshape(height, width, 3)


def keep_whole_depth(view):
    """Stops the view's corner renderers (the orientation axes') from drawing: hidden or not,
    they clear the depth of their corner, where drawn_covered could then go by colour alone.
    For measuring views only."""
    renderers = view.GetRenderWindow().GetRenderers()
    renderers.InitTraversal()
    for _ in range(renderers.GetNumberOfItems()):
        renderer = renderers.GetNextItem()
        if renderer.GetLayer() > 0 and renderer.GetErase() and tuple(renderer.GetViewport()) != (0.0, 0.0, 1.0, 1.0):
            renderer.DrawOff()


def drawn_covered(view, background):
    """The pixels the view's last frame covered, without rendering it again, (height, width)
    bool: those not in the `background` colour (RGB 0-255) or nearer than the far plane. The
    colour alone cannot tell (a lit surface may take the background's exact colour), nor the
    depth alone where a corner renderer cleared it (keep_whole_depth stops that)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter
    grab = vtkWindowToImageFilter()
    grab.SetInput(view.GetRenderWindow())
    grab.ShouldRerenderOff()
    grab.ReadFrontBufferOff()
    grab.SetInputBufferTypeToZBuffer()
    grab.Update()
    image = grab.GetOutput()
    width, height, _ = image.GetDimensions()
    depth = vtk_to_numpy(image.GetPointData().GetScalars()).reshape(height, width)
    return (depth < 1.0) | np.any(drawn_pixels(view) != np.asarray(background), axis=2)


def save_png(pixels, path):
    """Writes (height, width, 3) pixels (0-255) as a PNG."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOImage import vtkPNGWriter
    height, width, _ = pixels.shape
    image = vtkImageData()
    image.SetDimensions(width, height, 1)
    image.GetPointData().SetScalars(numpy_to_vtk(pixels.reshape(-1, 3).astype(np.uint8), deep=1))
    writer = vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputData(image)
    writer.Write()


def cell_ids(pixels):
    """The cell-id colouring decoded: 0 for background, else 1 + i + nx (j + ny k)."""
    return pixels[..., 0] + 256 * pixels[..., 1] + 65536 * pixels[..., 2]


def erode(mask, steps, corners=False):
    """The mask shrunk by `steps` pixels (4-neighbourhood, or 8 with `corners`)."""
    out = mask.copy()
    for _ in range(steps):
        shrunk = out.copy()
        shrunk[1:, :] &= out[:-1, :]
        shrunk[:-1, :] &= out[1:, :]
        shrunk[:, 1:] &= out[:, :-1]
        shrunk[:, :-1] &= out[:, 1:]
        if corners:
            shrunk[1:, 1:] &= out[:-1, :-1]
            shrunk[1:, :-1] &= out[:-1, 1:]
            shrunk[:-1, 1:] &= out[1:, :-1]
            shrunk[:-1, :-1] &= out[1:, 1:]
        out = shrunk
    return out


def stock_cell_id_filter(grid_reader, dims):
    """A ProgrammableFilter adding cell array CellIdColor: the RGB of 1 + i + nx (j + ny k),
    the Multiresolution Surface's Cell Id colouring, from the reader's I, J, K arrays."""
    from paraview import simple
    script = f"""
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk
data = self.GetInputDataObject(0, 0)
out = self.GetOutputDataObject(0)
out.ShallowCopy(data)
cd = data.GetCellData()
i = vtk_to_numpy(cd.GetArray('I')).astype(np.int64) - 1
j = vtk_to_numpy(cd.GetArray('J')).astype(np.int64) - 1
k = vtk_to_numpy(cd.GetArray('K')).astype(np.int64) - 1
ids = i + {dims[0]} * (j + {dims[1]} * k) + 1
rgb = np.stack([ids & 255, (ids >> 8) & 255, (ids >> 16) & 255], axis=1).astype(np.uint8)
array = numpy_to_vtk(rgb, deep=1)
array.SetName('CellIdColor')
out.GetCellData().AddArray(array)
"""
    return simple.ProgrammableFilter(Input=grid_reader, Script=script, OutputDataSetType="Same as Input")


def fail(message):
    print("FAIL", message)
    sys.exit(1)


def run_resmr(*command):
    """Runs the resmr tool (RESMR_EXECUTABLE) and fails on a non-zero exit."""
    import subprocess
    subprocess.run([os.environ["RESMR_EXECUTABLE"], *command], capture_output=True, text=True, check=True)


def faulted_synthetic(temp):
    """The faulted 90 x 70 x 12 synthetic model the image tests share (generated once)."""
    path = os.path.join(temp, "faulted.EGRID")
    if not os.path.exists(path):
        run_resmr("synth", "90", "70", "12", "-o", path, "--faults", "6", "--throw", "0.4", "--quiet")
    return path


def image_models(data, temp):
    """The models the image tests share: (name, grid file) for Reek, Brugge and the faulted
    synthetic model."""
    return [
        ("reek", os.path.join(data, "reek/res2df_sim/eclipse/model/2_R001_REEK-0.EGRID")),
        ("brugge", os.path.join(data, "brugge/Real0/BRUGGE_0000.EGRID")),
        ("faulted", faulted_synthetic(temp)),
    ]


def show_cell_ids(proxy, view):
    """Shows a Multiresolution Surface `proxy` in its exact Cell Id colouring (0 px, no grid
    lines, unlit, waiting for full detail); returns the display."""
    from paraview import simple
    display = simple.Show(proxy, view)
    display.PaintBy = "Cell Id"
    display.GridLines = 0
    display.PixelTolerance = 0
    display.WaitForDetailMs = 120000
    unlit(display)
    return display


def show_stock_cell_ids(source, view):
    """Shows a stock source carrying CellIdColor (stock_cell_id_filter) as a surface in those
    colours, unlit; returns the display."""
    from paraview import simple
    display = simple.Show(source, view)
    display.SetRepresentationType("Surface")
    simple.ColorBy(display, ("CELLS", "CellIdColor"))
    display.MapScalars = 0
    unlit(display)
    return display


def beside_neighbour_cell(ids, dims):
    """Per pixel of a cell-id image: whether a pixel around it (3 x 3) names a cell one step
    away in I, J or K (the edge of that cell's face, where cell coordinates round to this one)."""
    nx, ny, _ = dims
    n = ids.astype(np.int64) - 1
    found = np.zeros(ids.shape, dtype=bool)
    padded = np.pad(n, 1, constant_values=-1)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            other = padded[1 + dy:1 + dy + n.shape[0], 1 + dx:1 + dx + n.shape[1]]
            step = np.abs(other - n)
            found |= (other >= 0) & ((step == 1) | (step == nx) | (step == nx * ny))
    return found & (n >= 0)


def compare_cell_ids(view, bounds, cameras, label, stock_source, ours_proxy, show_only, capture, wrong_pixels,
                     failures):
    """Cell-id images of stock's `stock_source` and `ours_proxy` from each camera (name,
    direction, zoom): per view the share of the pixels both cover that name the same cell
    (>= 99.5% with 2000 pixels or more), pixels `wrong_pixels(got, expected)` counts (none;
    it returns the count and a phrase for the log) and background pixels of ours inside stock's
    cells (none); over the views >= 99.5% and 2% of the view covered. Failures are appended to
    `failures`; returns the pixels that agree and those both cover."""
    from paraview import simple
    same = covered = 0
    for camera_name, direction, zoom in cameras:
        name = f"{label}-{camera_name}"
        show_only(stock_source)
        place_camera(view, bounds, 1.0, direction, zoom)
        expected = cell_ids(capture(f"{name}-stock.png"))
        show_only(ours_proxy)
        simple.Render(view)
        got = cell_ids(capture(f"{name}-ours.png"))
        both = (expected > 0) & (got > 0)
        agree = float(np.mean(expected[both] == got[both])) if both.any() else 0.0
        wrong, note = wrong_pixels(got, expected)
        holes = int(np.sum(erode(expected > 0, 1, corners=True) & (got == 0)))
        print(f"{name}: {100 * agree:.2f}% of {int(both.sum())} pixels name the same cell; {note}; {holes} holes")
        same += int(np.sum(expected[both] == got[both]))
        covered += int(both.sum())
        if both.sum() >= 2000 and agree < 0.995:
            failures.append(f"{name}: {100 * agree:.2f}% < 99.5%")
        if wrong:
            failures.append(f"{name}: {note}")
        if holes:
            failures.append(f"{name}: {holes} background pixels inside stock's cells")
    share = same / (covered or 1)
    width, height = view.ViewSize
    print(f"{label}: {100 * share:.2f}% of {covered} pixels over {len(cameras)} views")
    if covered < 0.02 * width * height or share < 0.995:
        failures.append(f"{label}: {100 * share:.2f}% of {covered} pixels over the views")
    return same, covered


def check_alone(view, bounds, cameras, label, capture, wrong_pixels, failures):
    """Ours alone (what is shown) from each camera, in cell ids: something drawn, and no pixel
    `wrong_pixels(got)` counts (it returns the count and a phrase for the log)."""
    from paraview import simple
    for camera_name, direction, zoom in cameras:
        place_camera(view, bounds, 1.0, direction, zoom)
        simple.Render(view)
        got = cell_ids(capture(f"{label}-{camera_name}.png"))
        wrong, note = wrong_pixels(got)
        print(f"{label} {camera_name}: {int(np.sum(got > 0))} pixels, {note}")
        if wrong or not np.any(got > 0):
            failures.append(f"{label} {camera_name}: {note}, {int(np.sum(got > 0))} pixels")


def compare_colors(view, bounds, cameras, label, stock_source, ours_proxy, show_only, capture, failures):
    """Colour images of stock and ours (both coloured and unlit by the caller) from each camera:
    >= 99% of the pixels both cover within 3 levels a channel, over at least 2000 pixels."""
    from paraview import simple
    for camera_name, direction, zoom in cameras:
        name = f"{label}-{camera_name}"
        show_only(stock_source)
        place_camera(view, bounds, 1.0, direction, zoom)
        expected = capture(f"{name}-stock.png")
        show_only(ours_proxy)
        simple.Render(view)
        got = capture(f"{name}-ours.png")
        both = (expected.sum(axis=2) > 0) & (got.sum(axis=2) > 0)
        close = np.abs(expected.astype(int) - got.astype(int)).max(axis=2) <= 3
        share = float(np.mean(close[both])) if both.any() else 0.0
        print(f"{name}: {100 * share:.2f}% of {int(both.sum())} pixels within 3 levels of stock")
        if share < 0.99 or both.sum() < 2000:
            failures.append(f"{name}: {100 * share:.2f}% of {int(both.sum())} pixels < 99%")


def unlit(display):
    """Ambient light only: colours come out as the lookup table or cell-id colouring gives them."""
    display.Ambient = 1.0
    display.Diffuse = 0.0
    display.Specular = 0.0


def damage_wall_table(path, out):
    """Writes to `out` a copy of the .resmr `path` with one byte of its wall depth table (model
    chunk kind 5) changed: the viewer warns and paints walls from their coordinates, as files
    without the table. The index (192-byte region records, as many as the header's count at
    byte 128, then 32-byte model records: kind, part, offset, stored size) finds the chunk.
    False if the file has not exactly one wall depth chunk."""
    import struct
    with open(path, "rb") as source:
        data = bytearray(source.read())
    index_offset, index_size = struct.unpack_from("<QQ", data, len(data) - 32)
    first_model = index_offset + 192 * struct.unpack_from("<Q", data, 128)[0]
    records = [struct.unpack_from("<IIQI", data, p) for p in range(first_model, index_offset + index_size, 32)]
    walls = [r for r in records if r[0] == 5]
    if len(walls) != 1:
        return False
    data[walls[0][2] + walls[0][3] // 2] ^= 0x5A
    with open(out, "wb") as target:
        target.write(data)
    return True
