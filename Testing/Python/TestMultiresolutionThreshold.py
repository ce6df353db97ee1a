"""Multiresolution Threshold (the property filter) against stock ParaView's Threshold of the
full grid, pixel by pixel.

Reek, Brugge and a faulted synthetic model are built with `resmr build` and `resmr
add-properties`; property ranges (a static array, and a dynamic one at the first and last
report steps; one with an I/J/K box besides) are drawn by stock ParaView (EGRIDReader,
Threshold on the array and on ACTNUM, Surface, one colour a cell encoding 1 + i + nx (j + ny
k), unlit) and by the Multiresolution Surface of Multiresolution Threshold at tolerance 0 in
its Cell Id mode, from 4 cameras. Checks:
- >= 99.5% of the pixels both cover name the same cell (each view with enough pixels, and
  over the views of a filter);
- every pixel of ours names a cell stock's Threshold keeps (or, in Cell Id mode, lies on the
  edge of a kept neighbour's face);
- no background pixel of ours where stock covers the pixel and its 8 neighbours;
- with Layer 3, every pixel of ours names a kept cell of layer 3;
- at a tolerance of 8 px, every pixel of ours still names a cell the filter keeps; at 32 px
  (these models' crossed regions still their leaves: a block is wider than 32 px here) every
  inner pixel of stock's covered and >= 99.9% of ours naming a kept cell; at 128 px (crossed
  regions drawn coarse, masked by layer blocks) >= 95% as many pixels covered as stock's, and
  the share of ours naming a kept cell printed (the real image error of the approximation);
- the filter's Scalars list is the property file's arrays and its thresholds default to the
  array's range at the step;
- Reek's SWAT filtered and painted by SWAT, at the first and last steps, through ParaView's
  lookup table (unlit): >= 99% of the pixels both cover within 3 levels of stock's (the faces
  a filter exposes carry their cells' values);
- bad input (Reek): a filter on an array the property file lacks and a model without its
  property file draw nothing and say why in LastError (naming the array or the file); the
  same display, given a valid filter again, draws and clears LastError. (Filter text that is
  not "low high name" lines: Core.ViewSelection.)
Images are left in the temporary folder."""
import builtins
import os

import numpy as np
from paraview import servermanager, simple
from vtkmodules.util.numpy_support import vtk_to_numpy

import resmr_testing as rt

# The stock cell-id ProgrammableFilter runs its script in this module's globals: no global here
# may be named as its variables (array, ids, data, out, ...).
args = rt.arguments()
rt.load_plugin(args.plugin)
temp = os.path.join(args.temp, "threshold")
os.makedirs(temp, exist_ok=True)
WIDTH, HEIGHT = 640, 480
CAMERAS = [("above", [0.3, -0.5, 0.8], 1.0), ("below", [-0.4, 0.5, -0.7], 1.0),
           ("oblique", [1.0, -0.3, 0.35], 1.3), ("side", [-0.9, -0.6, 0.2], 1.2)]
failures = []


def capture(name):
    return rt.capture_rgb(view, os.path.join(temp, name), WIDTH, HEIGHT)


def cell_values(source, array_name):
    """The active cells' (cell id, value of `array_name`) of the full grid at the scene's time."""
    source.UpdatePipeline(simple.GetAnimationScene().AnimationTime)
    grid = servermanager.Fetch(source)
    data = grid.GetCellData()
    rgb = vtk_to_numpy(data.GetArray("CellIdColor")).astype(np.int64)
    cells = rgb[:, 0] + (rgb[:, 1] << 8) + (rgb[:, 2] << 16)
    values = vtk_to_numpy(data.GetArray(array_name)).astype(np.float32)
    active = vtk_to_numpy(data.GetArray("ACTNUM")) > 0
    return cells[active], values[active]


def thresholds(values, low_quantile, high_quantile):
    """Float32 bounds at two quantiles of the values (exact in both viewers' comparisons)."""
    finite = values[np.isfinite(values)]
    return [float(np.float32(np.quantile(finite, q))) for q in (low_quantile, high_quantile)]


def stock_threshold(source, array_name, low, high, box=None):
    out = simple.Threshold(Input=source, Scalars=["CELLS", array_name], LowerThreshold=low, UpperThreshold=high)
    made.append(out)
    for axis, name in enumerate(("I", "J", "K") if box else ()):
        out = simple.Threshold(Input=out, Scalars=["CELLS", name], LowerThreshold=box[2 * axis],
                               UpperThreshold=box[2 * axis + 1])
        made.append(out)
    out = simple.Threshold(Input=out, Scalars=["CELLS", "ACTNUM"], LowerThreshold=1, UpperThreshold=3)
    made.append(out)
    return out


def removed_pixels(got, kept):
    """Pixels of ours naming a cell the filter removes, except where a face of a kept cell
    neighbouring that cell (one step in I, J or K) shows in the 8 pixels around: there the
    pixel is on the edge between the two cells' faces, and a fragment at an edge may take its
    cell coordinate a hair across it (Cell Id mode only; property colours come with the face)."""
    failing = np.argwhere((got > 0) & ~np.isin(got, kept))
    nx, ny = dims[0], dims[1]

    def ijk(cell_id):
        n = int(cell_id) - 1
        return np.array([n % nx, (n // nx) % ny, n // (nx * ny)])

    kept_set = set(int(c) for c in kept)
    unexplained = 0
    for y, x in failing:
        cell = ijk(got[y, x])
        around = got[builtins.max(y - 1, 0):y + 2, builtins.max(x - 1, 0):x + 2].ravel()
        if not any(int(c) in kept_set and np.abs(ijk(c) - cell).sum() == 1 for c in around if c > 0):
            unexplained += 1
    return unexplained, len(failing)


def show_only(proxy):
    for other in shown:
        simple.Hide(other, view)
    simple.Show(proxy, view)


def covered_pixels(name):
    return int(np.sum(rt.cell_ids(capture(name)) > 0))


def last_error(display):
    display.UpdatePropertyInformation()
    return display.GetPropertyValue("LastError") or ""


def check_error_paths(resmr_path, reader, threshold, ours, bounds):
    """A filter the property file cannot answer and no property file: nothing drawn, LastError
    names the cause; a valid filter draws again."""
    show_only(threshold)
    rt.place_camera(view, bounds, 1.0, CAMERAS[0][1], CAMERAS[0][2])
    threshold.Scalars = ["CELLS", "NOSUCHARRAY"]
    simple.Render(view)
    error, pixels = last_error(ours), covered_pixels("error-no-array.png")
    print(f"filter on a missing array: {pixels} pixels, LastError {error!r}")
    if "NOSUCHARRAY" not in error or pixels:
        failures.append(f"missing array: LastError {error!r}, {pixels} pixels drawn")
    threshold.Scalars = ["CELLS", "PORO"]
    threshold.LowerThreshold, threshold.UpperThreshold = -1e30, 1e30
    simple.Render(view)
    error, pixels = last_error(ours), covered_pixels("error-recovered.png")
    print(f"valid filter again: {pixels} pixels, LastError {error!r}")
    if error or not pixels:
        failures.append(f"after a valid filter: LastError {error!r}, {pixels} pixels")
    # The model alone, its property file elsewhere: a property filter cannot be answered.
    alone = os.path.join(temp, "alone")
    os.makedirs(alone, exist_ok=True)
    alone_path = os.path.join(alone, os.path.basename(resmr_path))
    if not os.path.exists(alone_path):
        os.symlink(resmr_path, alone_path)
    lone = simple.OpenDataFile(alone_path)
    lone_threshold = simple.MultiresolutionThreshold(Input=lone)
    lone_threshold.Scalars = ["CELLS", "PORO"]
    lone_threshold.LowerThreshold, lone_threshold.UpperThreshold = 0.0, 1.0
    lone_display = rt.show_cell_ids(lone_threshold, view)
    shown.append(lone_threshold)
    show_only(lone_threshold)
    simple.Render(view)
    error, pixels = last_error(lone_display), covered_pixels("error-no-property-file.png")
    print(f"no property file: {pixels} pixels, LastError {error!r}")
    if ".resmrp" not in error or pixels:
        failures.append(f"no property file: LastError {error!r}, {pixels} pixels")
    shown.remove(lone_threshold)
    for proxy in (lone_threshold, lone):
        simple.Delete(proxy)
    show_only(threshold)


def compare_views(label, stock_source, ours_proxy, kept):
    """Cell-id images of stock and ours from the 4 cameras (resmr_testing.compare_cell_ids)."""
    def removed(got, _):
        failing, at_edges = removed_pixels(got, kept)
        return failing, (f"{failing} of ours name a cell the filter removes away from a kept neighbour's edge "
                         f"({at_edges} in all)")
    rt.compare_cell_ids(view, bounds, CAMERAS, label, stock_source, ours_proxy, show_only, capture, removed, failures)


def check_colors(label, stock_source, threshold, ours, array_name):
    """The filtered view painted by `array_name` against stock's, unlit, one camera."""
    stock = simple.Show(stock_source, view)
    stock.SetRepresentationType("Surface")
    stock.MapScalars = 1  # the same display showed cell-id colours before
    simple.ColorBy(stock, ("CELLS", array_name))
    stock.RescaleTransferFunctionToDataRange(False, False)
    unlit(stock)
    ours.PaintBy = "Property"
    simple.ColorBy(ours, ("CELLS", array_name))
    shown.append(stock_source)
    rt.compare_colors(view, bounds, [CAMERAS[2]], f"{label}-colors-{array_name}", stock_source, threshold, show_only,
                      capture, failures)
    ours.PaintBy = "Cell Id"
    simple.Hide(stock_source, view)


unlit = rt.unlit
view = rt.image_view(WIDTH, HEIGHT)
view.EnableRenderOnInteraction = 0
scene = simple.GetAnimationScene()
for name, grid_path in rt.image_models(args.data, temp):
    resmr_path = os.path.join(temp, name + ".resmr")
    if not os.path.exists(resmr_path):
        rt.run_resmr("build", grid_path, "-o", resmr_path, "--quiet")
    if not os.path.exists(resmr_path + "p"):
        rt.run_resmr("add-properties", resmr_path, grid_path)
    stock_reader = simple.EGRIDReader(FileName=grid_path)
    stock_reader.UpdatePipeline()
    grid = servermanager.Fetch(stock_reader)
    dims = tuple(int(vtk_to_numpy(grid.GetCellData().GetArray(a)).max()) for a in ("I", "J", "K"))
    nx, ny, nk = dims
    bounds = stock_reader.GetDataInformation().GetBounds()
    id_source = rt.stock_cell_id_filter(stock_reader, dims)
    made = []
    scene.UpdateAnimationUsingDataTimeSteps()
    times = list(stock_reader.TimestepValues) or [0.0]
    dynamic = "SWAT" if grid.GetCellData().GetArray("SWAT") else None

    reader = simple.OpenDataFile(resmr_path)
    reader.UpdatePipeline(times[0])  # the Scalars list comes from the descriptor's arrays
    threshold = simple.MultiresolutionThreshold(Input=reader)
    threshold.UpdatePipelineInformation()
    domain = threshold.SMProxy.GetProperty("SelectInputScalars").GetDomain("array_list")
    listed = sorted(domain.GetString(n) for n in range(domain.GetNumberOfStrings()))
    print(f"{name}: {nx} x {ny} x {nk}; Scalars offered {listed}")
    if "PORO" not in listed or (dynamic and dynamic not in listed):
        failures.append(f"{name}: Scalars offers {listed}")
    ours = rt.show_cell_ids(threshold, view)
    shown = [threshold]

    cases = [("poro", "PORO", 0.5, 1.0, times[0], None)]
    if dynamic:
        # The cells of least water (oil-bearing), where the front has not reached.
        cases += [("swat-first", dynamic, 0.0, 0.15, times[0], None),
                  ("swat-last", dynamic, 0.0, 0.1, times[-1], None)]
    box = [nx // 4 + 1, 3 * nx // 4, 1, ny, 2, builtins.max(2, nk - 1)]
    cases.append(("poro-box", "PORO", 0.25, 0.75, times[0], box))
    subset = None
    for tag, array_name, low_q, high_q, time, voi in cases:
        scene.AnimationTime = time
        _, values = cell_values(id_source, array_name)
        low, high = thresholds(values, low_q, high_q)
        threshold.Scalars = ["CELLS", array_name]
        threshold.LowerThreshold = low
        threshold.UpperThreshold = high
        ours_proxy = threshold
        if voi:
            subset = simple.MultiresolutionExtractSubset(Input=threshold)
            subset.VOI = voi
            made.append(subset)
            chained = rt.show_cell_ids(subset, view)
            shown.append(subset)
            ours_proxy = subset
        stock_source = stock_threshold(id_source, array_name, low, high, voi)
        rt.show_stock_cell_ids(stock_source, view)
        shown.append(stock_source)
        kept, _ = cell_values(stock_source, array_name)
        label = f"{name}-{tag}"
        print(f"{label}: {array_name} {low:g} to {high:g} at t={time:g}{' in ' + str(voi) if voi else ''}: "
              f"{len(kept)} cells of {len(values)} kept")
        compare_views(label, stock_source, ours_proxy, kept)
        if tag == "swat-last" and name == "reek":
            check_colors(label, stock_source, threshold, ours, array_name)
        if tag == "poro":
            # A coarse tolerance: regions a filter crosses are split to the leaves.
            show_only(threshold)
            ours.PixelTolerance = 8
            def removed_alone(got):
                failing, at_edges = removed_pixels(got, kept)
                return failing, f"{failing} name removed cells away from a kept neighbour's edge ({at_edges} in all)"
            rt.check_alone(view, bounds, CAMERAS, f"{label}-8px", capture, removed_alone, failures)
            # With Layer set, that layer's passing cells.
            ours.Layer = 3
            rt.place_camera(view, bounds, 1.0, CAMERAS[0][1], CAMERAS[0][2])
            simple.Render(view)
            got = rt.cell_ids(capture(f"{label}-layer3.png"))
            named = got[got > 0].astype(np.int64) - 1
            off_layer = int(np.sum(named // (dims[0] * dims[1]) != 2))
            failing, at_edges = removed_pixels(got, kept)
            in_layer = int(np.sum((np.asarray(kept, dtype=np.int64) - 1) // (dims[0] * dims[1]) == 2))
            print(f"{label}, Layer 3: {named.size} pixels ({in_layer} cells kept in it), {off_layer} off the layer, "
                  f"{failing} name removed cells "
                  f"away from a kept neighbour's edge ({at_edges} in all)")
            if off_layer or failing or (in_layer and named.size == 0):
                failures.append(f"{label} with Layer 3: {named.size} pixels, {off_layer} off the layer, {failing} removed")
            ours.Layer = 0
            # Coarser: regions the filter crosses drawn coarse, masked by layer blocks (cells
            # widened in I and J, never one that passes left out): the real image error.
            show_only(stock_source)
            rt.place_camera(view, bounds, 1.0, CAMERAS[0][1], CAMERAS[0][2])
            expected = rt.cell_ids(capture(f"{label}-coarse-stock.png"))
            show_only(threshold)
            for tolerance in (32, 128):
                ours.PixelTolerance = tolerance
                simple.Render(view)
                got = rt.cell_ids(capture(f"{label}-{tolerance}px.png"))
                covered = got > 0
                kept_share = float(np.mean(np.isin(got[covered], kept))) if covered.any() else 0.0
                missing = int(np.sum(rt.erode(expected > 0, 2, corners=True) & ~covered))
                print(f"{label} at {tolerance} px: {int(covered.sum())} pixels ({int(np.sum(expected > 0))} stock's), "
                      f"{100 * kept_share:.2f}% name a kept cell; {missing} of stock's inner pixels not covered")
                # At 32 px these models' crossed regions are still their leaves; at 128 px they
                # are drawn coarse, their silhouette within the tolerance of stock's.
                exact = tolerance == 32
                if (exact and (missing or kept_share < 0.999)) or covered.sum() < 0.95 * np.sum(expected > 0):
                    failures.append(f"{label} at {tolerance} px: {missing} of stock's pixels not covered, "
                                    f"{int(covered.sum())} covered, {100 * kept_share:.2f}% name kept cells")
            ours.PixelTolerance = 0
        simple.Hide(stock_source, view)
        if voi:
            simple.Hide(subset, view)
    if name == "reek" and dynamic:
        scene.AnimationTime = times[0]
        _, values = cell_values(id_source, dynamic)
        low, high = thresholds(values, 0.0, 0.15)
        threshold.Scalars = ["CELLS", dynamic]
        threshold.LowerThreshold = low
        threshold.UpperThreshold = high
        check_colors(f"{name}-swat-first", stock_threshold(id_source, dynamic, low, high), threshold, ours, dynamic)
    scene.AnimationTime = times[0]
    if name == "reek":
        check_error_paths(resmr_path, reader, threshold, ours, bounds)

    ours.UpdatePropertyInformation()
    error = ours.GetPropertyValue("LastError")
    if error:
        failures.append(f"{name}: LastError {error}")
    for proxy in reversed(made):
        simple.Delete(proxy)
    for proxy in (threshold, id_source, reader, stock_reader):
        simple.Delete(proxy)

if failures:
    rt.fail("; ".join(failures))
print("Multiresolution Threshold agrees with stock ParaView's Threshold")
