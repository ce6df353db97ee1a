"""Picking a cell on the Multiresolution Surface (PickAt and the Picked* readouts).

On Reek, Brugge and a synthetic faulted model, each with its property file, drawn in the Cell
Id colouring (grid coordinates on both sides, ApplyMapAxes=0), at 0 px and 8 px, from above and
from the side, 100 random covered pixels a camera (200 a model and tolerance):
- the picked (I, J, K) is the cell the same frame's Cell Id colouring shows at that pixel, on
  every pixel: the pick draws the frame's own cut;
- at 0 px it is stock ParaView's cell under that pixel (EGRIDReader, Surface, the same
  colouring) on >= 99% of them (the two draw different meshes of the same faces, and a pixel
  on a cell's edge may go either way; the surface test holds them to 99.5% of all pixels);
- the picked cell's values are EGRIDReader's for that cell, every array both have, at the first
  time step (an inactive cell, which coarse faces reach over, has none: NaN); whether it is
  active is EGRIDReader's ACTNUM;
- its corners are EGRIDReader's corners of that cell within a millionth of the model's extent
  (the finest level's, whatever is drawn), and the point picked at 0 px lies within them
  where stock shows the same cell;
- a pick on the background names nothing; InspectCell off the grid raises an error naming the
  file and the grid's size;
- in the single-layer view (layer 2), 50 picks name the cell its frame shows, in layer 2;
- stock grids (EGRIDReader, GRDECLReader) list I, J, K first among their cell arrays, as
  ParaView's hover shows them;
- resmr_inspect.InspectCell(I, J, K) gives EGRIDReader's corners and values for random top
  cells, and GoToCell puts the cell at the view's centre (a pick there names it) and outlines
  it (the 'Selected Cell' source); GoToPoint on the middle of its top face selects it.
Images of failures are left in the temporary folder."""
import os

import numpy as np
from paraview import servermanager, simple
from vtkmodules.util.numpy_support import vtk_to_numpy

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
import resmr_inspect  # noqa: E402 (the plugin carries it)
temp = os.path.join(args.temp, "pick")
os.makedirs(temp, exist_ok=True)
WIDTH, HEIGHT = 640, 480
PICKS = 100
rng = np.random.default_rng(7)


def models():
    return rt.image_models(args.data, temp)


def pick(display, view, x, y):
    """resmr_inspect.PickCell: (I, J, K), active (-1 unknown), point, corners (8, 3; NaN when
    unknown), {name: value}; (0, 0, 0) over the background."""
    cell = resmr_inspect.PickCell(x, y, view, display)
    if cell is None:
        return (0, 0, 0), -1, None, None, {}
    corners = np.full((8, 3), np.nan) if cell["corners"] is None else np.array(cell["corners"])
    active = -1 if cell["active"] is None else int(cell["active"])
    return (cell["I"], cell["J"], cell["K"]), active, np.array(cell["point"]), corners, cell["values"]


def stock_cells(grid):
    """Row of each (I, J, K) in the stock grid, its arrays and its cells' corners."""
    data = grid.GetCellData()
    ijk = np.stack([vtk_to_numpy(data.GetArray(a)).astype(np.int64) for a in ("I", "J", "K")], axis=1)
    rows = {tuple(c): n for n, c in enumerate(ijk.tolist())}
    points, cells = rt.points_and_cells(grid)
    return rows, points, cells


def check_values(label, values, grid, row, failures):
    """The picked values against the stock grid's cell arrays of the same names."""
    data = grid.GetCellData()
    compared = 0
    for name, value in values.items():
        array = data.GetArray(name)
        if array is None or array.GetNumberOfComponents() != 1:
            continue
        expected = float(np.float32(array.GetTuple1(row)))
        compared += 1
        same = (np.isnan(expected) and np.isnan(value)) or abs(expected - value) <= 1e-6 * float(np.maximum(1.0, abs(expected)))
        if not same:
            failures.append(f"{label}: {name} = {value}, EGRIDReader {expected}")
    return compared


view = rt.image_view(WIDTH, HEIGHT)
view.EnableRenderOnInteraction = 0
failures = []
for name, grid_path in models():
    resmr_path = os.path.join(temp, name + ".resmr")
    if not os.path.exists(resmr_path + "p"):
        rt.run_resmr("build", grid_path, "-o", resmr_path, "--quiet")
        rt.run_resmr("add-properties", resmr_path, grid_path)
    stock_reader = simple.EGRIDReader(FileName=grid_path, ApplyMapAxes=0)
    stock_reader.UpdatePipeline()
    grid = servermanager.Fetch(stock_reader, arg1=None, arg2=None, idx=0)
    dims = tuple(int(vtk_to_numpy(grid.GetCellData().GetArray(a)).max()) for a in ("I", "J", "K"))
    rows, points, cells = stock_cells(grid)
    first = [grid.GetCellData().GetArrayName(n) for n in range(3)]
    if first != ["I", "J", "K"]:
        failures.append(f"{name}: EGRIDReader's first cell arrays are {first}, not I, J, K (hover lists them so)")
    # The file keeps corners within a millionth of the model's extent (float32).
    extent = float(np.linalg.norm(np.ptp(points, axis=0)))
    ids = rt.stock_cell_id_filter(stock_reader, dims)
    stock = simple.Show(ids, view)
    stock.SetRepresentationType("Surface")
    simple.ColorBy(stock, ("CELLS", "CellIdColor"))
    stock.MapScalars = 0
    rt.unlit(stock)
    reader = simple.OpenDataFile(resmr_path)
    reader.ApplyMapAxes = 0
    ours = simple.Show(reader, view)
    ours.PaintBy = "Cell Id"
    ours.GridLines = 0
    ours.WaitForDetailMs = 120000
    rt.unlit(ours)
    bounds = stock_reader.GetDataInformation().GetBounds()
    valued = 0
    for tolerance in (0.0, 8.0):
        ours.PixelTolerance = tolerance
        same_as_frame = same_as_stock = picked = 0
        for camera_name, direction, zoom in (("above", [0.3, -0.5, 0.8], 1.0), ("side", [1.0, -0.3, 0.25], 1.3)):
            tag = f"{name}-{camera_name}-{tolerance:g}px"
            simple.Hide(reader, view)
            simple.Show(ids, view)
            view.ResetCamera(False)
            rt.place_camera(view, bounds, 1.0, direction, zoom)
            expected = rt.cell_ids(rt.capture_rgb(view, os.path.join(temp, tag + "-stock.png"), WIDTH, HEIGHT))
            simple.Hide(ids, view)
            simple.Show(reader, view)
            got = rt.cell_ids(rt.capture_rgb(view, os.path.join(temp, tag + ".png"), WIDTH, HEIGHT))
            ys, xs = np.nonzero(got > 0)
            if len(xs) < 0.05 * WIDTH * HEIGHT:
                failures.append(f"{tag}: the model covers too few pixels ({len(xs)})")
                continue
            for n in rng.choice(len(xs), PICKS, replace=False):
                x, y = int(xs[n]), int(ys[n])
                cell, active, point, corners, values = pick(ours, view, x, y)
                index = got[y, x] - 1
                shown = (index % dims[0] + 1, index // dims[0] % dims[1] + 1, index // (dims[0] * dims[1]) + 1)
                picked += 1
                same_as_frame += cell == shown
                if cell != shown:
                    failures.append(f"{tag} pixel ({x}, {y}): picked {cell}, the frame shows {shown}")
                    continue
                if tolerance == 0 and expected[y, x] > 0:
                    same_as_stock += expected[y, x] == got[y, x]
                row = rows.get(cell)
                if row is None:
                    failures.append(f"{tag}: picked {cell}, which EGRIDReader does not have")
                    continue
                actnum = int(grid.GetCellData().GetArray("ACTNUM").GetTuple1(row))
                if active == -1:
                    # No leaf holds the column: it must have no active cell, and then neither
                    # corners nor values are known.
                    if actnum != 0 or not np.all(np.isnan(corners)):
                        failures.append(f"{tag} {cell}: column not found, ACTNUM {actnum}, corners {corners[0]}")
                    continue
                # Corners: the stock cell's eight points, whatever their order.
                stock_corners = points[cells[row]]
                span = float(np.max(np.ptp(stock_corners, axis=0))) or 1.0
                distances = np.linalg.norm(stock_corners[None, :, :] - corners[:, None, :], axis=2)
                missing = float(np.max(np.min(distances, axis=1)))
                if missing > 1e-6 * extent:
                    failures.append(f"{tag} {cell}: a corner {missing:.3g} from EGRIDReader's")
                low, high = corners.min(axis=0) - 1e-3 * span, corners.max(axis=0) + 1e-3 * span
                # Where stock shows another cell (the surface test's half a percent), the frame
                # itself names a cell off its face; the pick reports the frame.
                if tolerance == 0 and expected[y, x] == got[y, x] and not np.all((point >= low) & (point <= high)):
                    outside = np.maximum(low - point, point - high)
                    failures.append(f"{tag} {cell}: picked point {point} outside its corners by {outside} "
                                    f"(cell span {np.ptp(corners, axis=0)})")
                if actnum != active:
                    failures.append(f"{tag} {cell}: active {active}, ACTNUM {actnum}")
                if active == 0:
                    # No value: the layer tables hold NaN where the grid has no active cell
                    # (EGRIDReader fills 0), and coarse faces reach over such cells.
                    numbers = [v for v in values.values() if not np.isnan(v)]
                    if numbers:
                        failures.append(f"{tag} {cell}: inactive, yet values {numbers[:3]}")
                    continue
                valued += check_values(f"{tag} {cell}", values, grid, row, failures) > 0
            background = np.argwhere(got == 0)
            if len(background):
                y, x = (int(v) for v in background[len(background) // 2])
                cell = pick(ours, view, x, y)[0]
                if cell != (0, 0, 0):
                    failures.append(f"{tag}: a pick on the background ({x}, {y}) named {cell}")
        print(f"{name} at {tolerance:g} px: {same_as_frame} of {picked} picks name the frame's cell"
              + (f", {same_as_stock} stock's" if tolerance == 0 else ""))
        if tolerance == 0 and same_as_stock < 0.99 * picked:
            failures.append(f"{name}: {same_as_stock} of {picked} picks at 0 px name stock's cell (< 99%)")
    # The single-layer view: layer 2 alone, picks name its cells as its frame shows them.
    ours.Layer = 2
    ours.PixelTolerance = 0
    view.ResetCamera(False)
    rt.place_camera(view, bounds, 1.0, [0.3, -0.5, 0.8], 1.0)
    got = rt.cell_ids(rt.capture_rgb(view, os.path.join(temp, f"{name}-layer2.png"), WIDTH, HEIGHT))
    ys, xs = np.nonzero(got > 0)
    layer_same, count = 0, 50 if len(xs) > 50 else len(xs)  # (pvpython's numpy_interface replaces min)
    for n in rng.choice(len(xs), count, replace=False):
        x, y = int(xs[n]), int(ys[n])
        index = got[y, x] - 1
        shown = (index % dims[0] + 1, index // dims[0] % dims[1] + 1, index // (dims[0] * dims[1]) + 1)
        layer_same += pick(ours, view, x, y)[0] == shown and shown[2] == 2
    print(f"{name} layer 2: {layer_same} of {count} picks name the frame's cell, in layer 2")
    if not count or layer_same != count:
        failures.append(f"{name} layer 2: {layer_same} of {count} picks name the frame's cell")
    ours.Layer = 0
    # resmr_inspect, as users call it: InspectCell by I, J, K; GoToCell puts the cell at the
    # view's centre (a top cell, seen from above) and outlines it.
    ours.PixelTolerance = 0
    active_top = [c for c, n in rows.items() if c[2] == 1 and int(grid.GetCellData().GetArray("ACTNUM").GetTuple1(n))]
    for choice in rng.choice(len(active_top), 3, replace=False):
        i, j, k = active_top[int(choice)]
        inspected = resmr_inspect.InspectCell(i, j, k, view, ours)
        row = rows[(i, j, k)]
        stock_corners = points[cells[row]]
        if inspected is None or inspected["corners"] is None:
            failures.append(f"{name}: InspectCell({i}, {j}, {k}) found nothing")
            continue
        corners = np.array(inspected["corners"])
        distances = np.linalg.norm(stock_corners[None, :, :] - corners[:, None, :], axis=2)
        if float(np.max(np.min(distances, axis=1))) > 1e-6 * extent or not inspected["active"]:
            failures.append(f"{name}: InspectCell({i}, {j}, {k}) corners or activity differ from EGRIDReader's")
        check_values(f"{name} InspectCell({i}, {j}, {k})", inspected["values"], grid, row, failures)
        view.ResetCamera(False)
        rt.place_camera(view, bounds, 1.0, [0.1, -0.2, 1.0], 1.0)
        resmr_inspect.GoToCell(i, j, k, view, ours)
        centre = resmr_inspect.PickCell(WIDTH // 2, HEIGHT // 2, view, ours)
        outline = simple.FindSource("Selected Cell")
        print(f"{name}: GoToCell({i}, {j}, {k}): the view's centre shows "
              f"{None if centre is None else (centre['I'], centre['J'], centre['K'])}")
        if centre is None or (centre["I"], centre["J"], centre["K"]) != (i, j, k):
            failures.append(f"{name}: after GoToCell({i}, {j}, {k}) the view's centre is not the cell")
        if outline is None or len(outline.Points) != 48:
            failures.append(f"{name}: GoToCell({i}, {j}, {k}) left no outline of the cell")
        # GoToPoint: the middle of the cell's top face (map x, y and its depth) selects it.
        top = np.array(inspected["corners"][:4]).mean(axis=0)
        at = resmr_inspect.GoToPoint(float(top[0]), float(top[1]), float(-top[2]), view, ours)
        if at is None or (at["I"], at["J"], at["K"]) != (i, j, k):
            failures.append(f"{name}: GoToPoint on the top of ({i}, {j}, {k}) selected "
                            f"{None if at is None else (at['I'], at['J'], at['K'])}")
    simple.Delete(simple.FindSource("Selected Cell"))
    # Bad input: a cell off the grid is refused with a message naming the file and the grid.
    try:
        resmr_inspect.InspectCell(dims[0] + 1, 1, 1, view, ours)
        failures.append(f"{name}: InspectCell off the grid raised nothing")
    except RuntimeError as error:
        if os.path.basename(resmr_path) not in str(error) or f"{dims[0]} x {dims[1]} x {dims[2]}" not in str(error):
            failures.append(f"{name}: InspectCell off the grid: {error}")
    print(f"{name}: values compared with EGRIDReader on {valued} picks")
    if valued < 100:
        failures.append(f"{name}: values compared on {valued} picks only")
    simple.Delete(ours)
    simple.Delete(reader)
    simple.Delete(stock)
    simple.Delete(ids)
    simple.Delete(stock_reader)

# Stock grids: GRDECLReader's cells list I, J, K first too (ParaView's hover shows arrays in order).
deck = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Data", "demo_faulted_dome.grdecl")
first = [rt.read_grid(deck)[1].GetCellData().GetArrayName(n) for n in range(3)]
print(f"GRDECLReader's first cell arrays: {first}")
if first != ["I", "J", "K"]:
    failures.append(f"GRDECLReader's first cell arrays are {first}, not I, J, K")

if failures:
    for failure in failures[:40]:
        print("FAIL", failure)
    rt.fail(f"{len(failures)} failures")
print("OK")
