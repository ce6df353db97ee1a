"""Multiresolution Extract Subset (the I/J/K range filter) against stock ParaView on the full
grid, pixel by pixel.

Reek, Brugge and a faulted synthetic model are built with `resmr build`; boxes, I, J and K
slices are drawn by stock ParaView (EGRIDReader, Threshold on I, J, K and ACTNUM, Surface,
one colour a cell encoding 1 + i + nx (j + ny k), unlit) and by the Multiresolution Surface
of Multiresolution Extract Subset at tolerance 0 in its Cell Id mode, from 4 cameras. Checks:
- >= 99.5% of the pixels both cover name the same cell (each view with enough pixels, and
  over the views of a range);
- every pixel of ours names a cell in the range;
- no background pixel of ours where stock covers the pixel and its 8 neighbours;
- the filter's VOI sliders are bounded by the grid's dimensions; chained filters intersect;
  with Layer set, only that layer of the box is drawn;
- at a tolerance of 8 px every pixel of ours still names a cell in the range (coarse regions
  never cross a side of the range);
- an empty range draws nothing;
- stock Slice, Clip and Threshold applied to the .resmr (directly or after the filter) warn once,
  naming Multiresolution Extract Subset; on the full grid they do not;
- Reek's PORO, and SWAT at the first and last report steps, on a box and an I slice through
  ParaView's lookup table (unlit): >= 99% of the pixels both cover within 3 levels a channel
  of stock's (the cut faces painted from the planes of cells along each cut);
- Exclude: a pit from the top down and a corner of every layer hidden (stock: Python Calculator
  flagging the box's cells, Threshold keeping the others, and ACTNUM), 4 cameras each, the
  same three checks, no pixel naming a hidden cell; a coarse tolerance (8 px) never shows a
  hidden cell (but for edge pixels of a face beside the hidden cell, as cell ids round there);
  on Reek, PORO's colours on the faces the pit exposes as above.
Images are left in the temporary folder."""
import builtins
import os

import numpy as np
from paraview import servermanager, simple
from vtkmodules.util.numpy_support import vtk_to_numpy

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
temp = os.path.join(args.temp, "range")
os.makedirs(temp, exist_ok=True)
WIDTH, HEIGHT = 640, 480
unlit = rt.unlit


def models():
    return [
        ("reek", os.path.join(args.data, "reek/res2df_sim/eclipse/model/2_R001_REEK-0.EGRID")),
        ("brugge", os.path.join(args.data, "brugge/Real0/BRUGGE_0000.EGRID")),
        ("faulted", rt.faulted_synthetic(temp)),
    ]


def ranges(nx, ny, nk):
    """(tag, VOI from 1): a box inside, a box on the grid's limits, one slice a direction."""
    return [
        ("box", [nx // 4 + 1, 3 * nx // 4, ny // 5 + 1, 4 * ny // 5, 2, builtins.max(2, nk - 2)]),
        ("corner", [1, nx // 2, ny // 2, ny, nk // 2 + 1, nk]),
        ("islice", [nx // 2, nx // 2, 1, ny, 1, nk]),
        ("jslice", [1, nx, ny // 3, ny // 3, 1, nk]),
        ("kslab", [1, nx, 1, ny, builtins.max(1, nk // 3), builtins.max(1, nk // 3) + 1]),
    ]


def stock_range(source, voi):
    """Active cells with I, J, K in `voi`, as stock ParaView extracts them."""
    out = source
    for axis, name in enumerate(("I", "J", "K")):
        out = simple.Threshold(Input=out, Scalars=["CELLS", name], LowerThreshold=voi[2 * axis],
                               UpperThreshold=voi[2 * axis + 1])
        made.append(out)
    out = simple.Threshold(Input=out, Scalars=["CELLS", "ACTNUM"], LowerThreshold=1, UpperThreshold=3)
    made.append(out)
    return out


def capture(name):
    return rt.capture_rgb(view, os.path.join(temp, name), WIDTH, HEIGHT)


def show_only(proxy):
    for other in shown:
        simple.Hide(other, view)
    simple.Show(proxy, view)


def in_range(ids, voi, dims):
    """Per pixel of a cell-id image: whether its cell is in `voi` (background: True)."""
    nx, ny, _ = dims
    n = ids.astype(np.int64) - 1
    i, j, k = n % nx + 1, (n // nx) % ny + 1, n // (nx * ny) + 1
    inside = (i >= voi[0]) & (i <= voi[1]) & (j >= voi[2]) & (j <= voi[3]) & (k >= voi[4]) & (k <= voi[5])
    return inside | (ids == 0)


def stock_excluded(source, voi):
    """Active cells not in `voi`, as stock ParaView finds them."""
    flag = simple.PythonCalculator(Input=source, ArrayAssociation="Cell Data", ArrayName="InExcluded")
    flag.Expression = (f"((I >= {voi[0]}) & (I <= {voi[1]}) & (J >= {voi[2]}) & (J <= {voi[3]}) & "
                       f"(K >= {voi[4]}) & (K <= {voi[5]})).astype(int)")
    kept = simple.Threshold(Input=flag, Scalars=["CELLS", "InExcluded"], LowerThreshold=0, UpperThreshold=0)
    active = simple.Threshold(Input=kept, Scalars=["CELLS", "ACTNUM"], LowerThreshold=1, UpperThreshold=3)
    made.extend([flag, kept, active])
    return active


def check_exclude(name, reader, ids, stock_reader, dims):
    """Exclude boxes against stock, in cell ids, at 8 px, and (Reek) in PORO's colours."""
    nx, ny, nk = dims
    hole = simple.MultiresolutionExtractSubset(Input=reader)
    hole.Exclude = 1
    made.append(hole)
    display = rt.show_cell_ids(hole, view)
    shown.append(hole)
    # A pit from the top down to the layer above the bottom one, and a corner through every layer.
    boxes = [("exclude-box", [nx // 4 + 1, 3 * nx // 4, ny // 5 + 1, 4 * ny // 5, 1, builtins.max(1, nk - 1)]),
             ("exclude-corner", [1, nx // 2, 1, ny // 2, 1, nk])]
    for tag, voi in boxes:
        hole.VOI = voi
        stock_source = stock_excluded(ids, voi)
        rt.show_stock_cell_ids(stock_source, view)
        shown.append(stock_source)
        def hidden(got, _, voi=voi):
            count = int(np.sum(in_range(got, voi, dims) & (got > 0) & ~rt.beside_neighbour_cell(got, dims)))
            return count, f"{count} of ours name a hidden cell"
        rt.compare_cell_ids(view, bounds, cameras, f"{name}-{tag}", stock_source, hole, show_only, capture, hidden,
                            failures)
        simple.Hide(stock_source, view)
        if tag == "exclude-box":
            show_only(hole)
            display.PixelTolerance = 8
            def hidden_alone(got, voi=voi):
                count = int(np.sum(in_range(got, voi, dims) & (got > 0) & ~rt.beside_neighbour_cell(got, dims)))
                return count, f"{count} name hidden cells"
            rt.check_alone(view, bounds, cameras, f"{name}-{tag}-8px", capture, hidden_alone, failures)
            display.PixelTolerance = 0
            if name == "reek":
                # The hole's faces (inside the model) in PORO's colours, from their cells' values.
                display.PaintBy = "Property"
                simple.ColorBy(display, ("CELLS", "PORO"))
                stock = simple.Show(stock_source, view)
                stock.SetRepresentationType("Surface")
                stock.MapScalars = 1
                simple.ColorBy(stock, ("CELLS", "PORO"))
                stock.RescaleTransferFunctionToDataRange(False, False)
                unlit(stock)
                rt.compare_colors(view, bounds, cameras[:3], f"{name}-{tag}-poro", stock_source, hole, show_only,
                                  capture, failures)
                display.PaintBy = "Cell Id"
                stock.MapScalars = 0
                simple.ColorBy(stock, ("CELLS", "CellIdColor"))
                simple.Hide(stock_source, view)
    simple.Hide(hole, view)


def check_properties(subset, ours, stock_reader, bounds, dims):
    """PORO and SWAT (first and last step) on a box and an I slice, against stock, unlit."""
    nx, ny, nk = dims
    scene = simple.GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    times = list(stock_reader.TimestepValues)
    ours.PaintBy = "Property"
    for tag, voi in (ranges(nx, ny, nk)[0], ranges(nx, ny, nk)[2]):
        subset.VOI = voi
        stock_source = stock_range(stock_reader, voi)
        for array, time in (("PORO", times[0]), ("SWAT", times[0]), ("SWAT", times[-1])):
            scene.AnimationTime = time
            stock = simple.Show(stock_source, view)
            stock.SetRepresentationType("Surface")
            simple.ColorBy(stock, ("CELLS", array))
            stock.RescaleTransferFunctionToDataRange(False, False)
            unlit(stock)
            simple.ColorBy(ours, ("CELLS", array))
            shown.append(stock_source)
            rt.compare_colors(view, bounds, [cameras[2]], f"reek-{tag}-{array}-{time:g}", stock_source, subset,
                              show_only, capture, failures)
            simple.Hide(stock_source, view)
    scene.AnimationTime = times[0]
    ours.PaintBy = "Cell Id"


def warnings_while(make):
    """The proxy `make()` returns, and the VTK warnings printed meanwhile."""
    from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow
    window = vtkStringOutputWindow()
    previous = vtkOutputWindow.GetInstance()
    vtkOutputWindow.SetInstance(window)
    try:
        proxy = make()
    finally:
        vtkOutputWindow.SetInstance(previous)
    return proxy, window.GetOutput()


def check_stock_warnings(reader, subset, grid_reader):
    """Stock filters on the descriptor warn, naming the filter to use; on the full grid not."""
    cases = [("Slice", lambda: simple.Slice(Input=reader), True),
             ("Clip", lambda: simple.Clip(Input=subset), True),
             ("Threshold", lambda: simple.Threshold(Input=subset), True),
             ("Slice of the full grid", lambda: simple.Slice(Input=grid_reader), False)]
    for label, make, expected in cases:
        proxy, text = warnings_while(make)
        warned = "Multiresolution Extract Subset" in text
        print(f"{label}: {'warned' if warned else 'no warning'} {text.strip()[:160]!r}")
        if warned != expected or (expected and text.count("Multiresolution Extract Subset") != 1):
            failures.append(f"{label}: warning {text!r}, expected {'one' if expected else 'none'}")
        simple.Delete(proxy)


view = rt.image_view(WIDTH, HEIGHT)
view.EnableRenderOnInteraction = 0
failures = []
cameras = [("above", [0.3, -0.5, 0.8], 1.0), ("below", [-0.4, 0.5, -0.7], 1.0),
           ("oblique", [1.0, -0.3, 0.35], 1.3), ("side", [-0.9, -0.6, 0.2], 1.2)]
for name, grid_path in models():
    resmr_path = os.path.join(temp, name + ".resmr")
    if not os.path.exists(resmr_path):
        rt.run_resmr("build", grid_path, "-o", resmr_path, "--quiet")
    if name == "reek" and not os.path.exists(resmr_path + "p"):
        rt.run_resmr("add-properties", resmr_path, grid_path)
    stock_reader = simple.EGRIDReader(FileName=grid_path)
    stock_reader.UpdatePipeline()
    grid = servermanager.Fetch(stock_reader)
    dims = tuple(int(vtk_to_numpy(grid.GetCellData().GetArray(a)).max()) for a in ("I", "J", "K"))
    nx, ny, nk = dims
    bounds = stock_reader.GetDataInformation().GetBounds()
    ids = rt.stock_cell_id_filter(stock_reader, dims)
    made = []

    reader = simple.OpenDataFile(resmr_path)
    subset = simple.MultiresolutionExtractSubset(Input=reader)
    subset.UpdatePipelineInformation()
    voi_range = list(subset.GetPropertyValue("VOIRange"))
    print(f"{name}: {nx} x {ny} x {nk}; VOI default {list(subset.VOI)}, sliders {voi_range}")
    if voi_range != [1, nx, 1, nx, 1, ny, 1, ny, 1, nk, 1, nk]:
        failures.append(f"{name}: VOI sliders {voi_range}")
    if name == "reek":
        check_stock_warnings(reader, subset, stock_reader)
    ours = rt.show_cell_ids(subset, view)
    shown = [subset]

    for tag, voi in ranges(nx, ny, nk):
        subset.VOI = voi
        stock_source = stock_range(ids, voi)
        rt.show_stock_cell_ids(stock_source, view)
        shown.append(stock_source)
        def outside(got, expected, voi=voi):
            ours_out, stock_out = int(np.sum(~in_range(got, voi, dims))), int(np.sum(~in_range(expected, voi, dims)))
            return ours_out + stock_out, f"{ours_out} of ours out of the range ({stock_out} of stock's)"
        rt.compare_cell_ids(view, bounds, cameras, f"{name}-{tag}", stock_source, subset, show_only, capture, outside,
                            failures)
        simple.Hide(stock_source, view)

    # A coarse tolerance: regions a side of the range crosses are still split to the leaves,
    # so no pixel names a cell out of the range.
    show_only(subset)
    voi = ranges(nx, ny, nk)[0][1]
    subset.VOI = voi
    ours.PixelTolerance = 8
    for camera_name, direction, zoom in cameras:
        rt.place_camera(view, bounds, 1.0, direction, zoom)
        simple.Render(view)
        got = rt.cell_ids(capture(f"{name}-box8px-{camera_name}.png"))
        outside = int(np.sum(~in_range(got, voi, dims)))
        print(f"{name} box at 8 px {camera_name}: {int(np.sum(got > 0))} pixels, {outside} out of the range")
        if outside or not np.any(got > 0):
            failures.append(f"{name} box at 8 px {camera_name}: {outside} pixels out of the range")
    ours.PixelTolerance = 0

    # With Layer set, that layer of the box.
    ours.Layer = 3
    rt.place_camera(view, bounds, 1.0, cameras[0][1], cameras[0][2])
    simple.Render(view)
    got = rt.cell_ids(capture(f"{name}-box-layer3.png"))
    layer_voi = [voi[0], voi[1], voi[2], voi[3], 3, 3]
    outside = int(np.sum(~in_range(got, layer_voi, dims)))
    print(f"{name} box, Layer 3: {int(np.sum(got > 0))} pixels, {outside} out of {layer_voi}")
    if outside or not np.any(got > 0):
        failures.append(f"{name} box with Layer 3: {outside} pixels out of {layer_voi}, {int(np.sum(got > 0))} drawn")
    ours.Layer = 0

    # Chained filters intersect their boxes; a box holding no cell draws nothing.
    second = simple.MultiresolutionExtractSubset(Input=subset)
    second.VOI = [1, nx, 1, ny, 1, 2]
    made.append(second)
    chained = rt.show_cell_ids(second, view)
    simple.Hide(subset, view)
    rt.place_camera(view, bounds, 1.0, cameras[0][1], cameras[0][2])
    simple.Render(view)
    got = rt.cell_ids(capture(f"{name}-chained.png"))
    both_voi = [voi[0], voi[1], voi[2], voi[3], voi[4], builtins.min(voi[5], 2)]
    outside = int(np.sum(~in_range(got, both_voi, dims)))
    print(f"{name} chained {both_voi}: {int(np.sum(got > 0))} pixels, {outside} out of the range")
    if outside or not np.any(got > 0):
        failures.append(f"{name} chained: {outside} pixels out of {both_voi}, {int(np.sum(got > 0))} drawn")
    second.VOI = [1, nx, 1, ny, nk + 1, nk + 5]
    simple.Render(view)
    drawn = int(np.sum(rt.cell_ids(capture(f"{name}-empty.png")) > 0))
    print(f"{name} empty range: {drawn} pixels drawn")
    if drawn:
        failures.append(f"{name} empty range: {drawn} pixels drawn")
    simple.Hide(second, view)

    if name == "reek":
        check_properties(subset, ours, stock_reader, bounds, dims)
    simple.Hide(subset, view)
    check_exclude(name, reader, ids, stock_reader, dims)

    ours.UpdatePropertyInformation()
    error = ours.GetPropertyValue("LastError")
    if error:
        failures.append(f"{name}: LastError {error}")
    for proxy in reversed(made):
        simple.Delete(proxy)
    for proxy in (subset, ids, reader, stock_reader):
        simple.Delete(proxy)

if failures:
    rt.fail("; ".join(failures))
print("Multiresolution Extract Subset agrees with stock ParaView")
