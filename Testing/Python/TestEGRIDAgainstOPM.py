"""EGRIDReader against OPM's EclIO (an independent implementation, Debian's
python3-opm-common) on Reek, Brugge (per-step restarts, field units), SPE9 (90 steps) and
Egg: the 8 corners of every cell, every INIT array and every restart array of every report
step, value for value; report times; and that the output follows the GRDECL reader's
contract (I/J/K, ACTNUM, hidden inactive cells).
"""
import glob
import os

import numpy as np
from opm.io.ecl import EclFile, EGrid, ERst

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
DATA = args.data

MODELS = {
    "Reek": "reek/res2df_sim/eclipse/model/2_R001_REEK-0.EGRID",
    "Brugge": "brugge/Real0/BRUGGE_0000.EGRID",
    "SPE9": "spe9/opmflow2022_run_of_opm-data_SPE9_CP/SPE9_CP.EGRID",
    "Egg": "egg/opmflow2022_run_of_initial_guess_julia_deck/EGG_MODEL_ECL.EGRID",
}
# ECLIPSE corner (di + 2 dj + 4 dk) of each VTK hexahedron point.
ECLIPSE_CORNER_OF_VTK_POINT = np.array([0, 1, 3, 2, 4, 5, 7, 6])


def fetch(reader, time=None):
    from paraview import servermanager
    if time is None:
        reader.UpdatePipeline()
    else:
        reader.UpdatePipeline(time)
    return servermanager.Fetch(reader, arg1=None, arg2=None, idx=0)


def eclipse_order(grid, name, dims):
    """Cell array `name` in ECLIPSE cell order (i fastest, k down)."""
    nx, ny, _ = dims
    i, j, k = (rt.cell_array(grid, axis) - 1 for axis in "IJK")
    values = np.empty(len(i), rt.cell_array(grid, name).dtype)
    values[(k * ny + j) * nx + i] = rt.cell_array(grid, name)
    return values


def compare_corners(name, grid, egrid_path, dims):
    nx, ny, nz = dims
    reference = EGrid(egrid_path)
    points, hexahedra = rt.points_and_cells(grid)
    i, j, k = (rt.cell_array(grid, axis) - 1 for axis in "IJK")
    mirrored = nz > 1 and k[0] == nz - 1
    corner_of_point = ECLIPSE_CORNER_OF_VTK_POINT ^ (4 if mirrored else 0)
    ours = np.zeros((nx * ny * nz, 8, 3))
    ours[((k * ny + j) * nx + i)[:, None], corner_of_point[None, :]] = points[hexahedra]
    ours[..., 2] *= -1.0
    theirs = np.zeros_like(ours)
    for kk in range(nz):
        for jj in range(ny):
            for ii in range(nx):
                x, y, z = reference.xyz_from_ijk(ii, jj, kk)
                theirs[(kk * ny + jj) * nx + ii] = np.column_stack([x, y, z])
    # Both interpolate float32 pillars in double precision: equal to double rounding.
    tolerance = 1e-9 * max(1.0, np.abs(theirs).max())
    error = np.abs(ours - theirs).max()
    print(f"{name}: {len(ours)} cells, max corner difference {error:.3g} (tolerance {tolerance:.3g})")
    if not error <= tolerance:
        worst = np.unravel_index(np.abs(ours - theirs).max(axis=2).argmax(), ours.shape[:2])
        rt.fail(f"{name}: corners differ from OPM at cell {worst[0]} corner {worst[1]}: ours"
                f" {ours[worst]} OPM {theirs[worst]}")


def compare_cells(name, what, ours, theirs, active):
    """ours: per cell (ECLIPSE order); theirs: per active cell or per cell, from OPM."""
    theirs = np.asarray(theirs)
    if len(theirs) == len(ours):
        expected = theirs
        mask = np.ones(len(ours), bool)
    else:
        expected = np.full(len(ours), np.nan)
        expected[active] = theirs[: int(active.sum())]
        mask = active
    got = ours[mask].astype(np.float64)
    want = expected[mask].astype(np.float64)
    if not np.array_equal(got, want):
        bad = np.flatnonzero(got != want)
        rt.fail(f"{name}: {what}: {len(bad)} values differ from OPM, first at active value"
                f" {bad[0]}: ours {got[bad[0]]} OPM {want[bad[0]]}")
    if len(theirs) != len(ours) and ours.dtype.kind == "f" and not np.all(np.isnan(ours[~active])):
        rt.fail(f"{name}: {what}: inactive cells should hold NaN")


def restart_steps(egrid_path):
    """[(report number, {name: array})] per step from OPM, unified or per-step files."""
    stem = os.path.splitext(egrid_path)[0]
    if os.path.exists(stem + ".UNRST"):
        restart = ERst(stem + ".UNRST")
        return [(step, lambda name, step=step: restart[name, step]) for step in restart.report_steps], \
            sorted({name for step in restart.report_steps for name, _, _ in restart.arrays(step)})
    files = sorted(glob.glob(stem + ".X[0-9][0-9][0-9][0-9]"))
    steps = []
    names = set()
    for path in files:
        restart = EclFile(path)
        names.update(name for name, _, _ in restart.arrays)
        steps.append((int(path[-4:]), lambda name, restart=restart: restart[name]))
    return steps, sorted(names)


def check_model(name, relative_path):
    from paraview import simple
    path = os.path.join(DATA, relative_path)
    reader = simple.EGRIDReader(FileName=path, ApplyMapAxes=0)
    reader.UpdatePipelineInformation()
    times = list(reader.TimestepValues)
    grid = fetch(reader, times[0] if times else None)
    if reader.GetProperty("LastError").GetData():
        rt.fail(f"{name}: {reader.GetProperty('LastError').GetData()}")
    egrid = EclFile(path)
    head = np.asarray(egrid["GRIDHEAD"])
    dims = tuple(int(v) for v in head[1:4])
    actnum = np.asarray(egrid["ACTNUM"]) if "ACTNUM" in [a[0] for a in egrid.arrays] \
        else np.ones(np.prod(dims), np.int32)
    active = actnum > 0
    if grid.GetCells().GetNumberOfCells() != np.prod(dims):
        rt.fail(f"{name}: {grid.GetCells().GetNumberOfCells()} cells, expected {np.prod(dims)}")
    if not np.array_equal(eclipse_order(grid, "ACTNUM", dims), actnum):
        rt.fail(f"{name}: ACTNUM differs from the EGRID's")
    ghosts = eclipse_order(grid, "vtkGhostType", dims) if grid.GetCellData().GetArray("vtkGhostType") \
        else np.zeros(np.prod(dims), np.uint8)
    if not np.array_equal(ghosts != 0, ~active):
        rt.fail(f"{name}: hidden cells are not exactly the inactive ones")
    compare_corners(name, grid, path, dims)
    nnc_expected = sum(count for keyword, _, count in egrid.arrays if keyword == "NNC1")
    nnc = grid.GetFieldData().GetArray("NonNeighbourConnections").GetValue(0)
    if nnc != nnc_expected:
        rt.fail(f"{name}: NonNeighbourConnections {nnc}, the EGRID has {nnc_expected}")

    init = EclFile(os.path.splitext(path)[0] + ".INIT")
    init_names = [array_name for array_name, _, _ in init.arrays]
    checked = 0
    for array_name in reader.CellArrays:
        keyword = array_name[:-5] if array_name.endswith("_INIT") else array_name
        if keyword not in init_names or grid.GetCellData().GetArray(array_name) is None:
            continue
        compare_cells(name, f"INIT {keyword}", eclipse_order(grid, array_name, dims), init[keyword], active)
        checked += 1
    if checked < 5:
        rt.fail(f"{name}: only {checked} INIT arrays compared")

    steps, restart_names = restart_steps(path)
    if len(times) != len(steps):
        rt.fail(f"{name}: {len(times)} time steps, OPM finds {len(steps)} report steps")
    dynamic = [n for n in reader.CellArrays if n in restart_names and n not in init_names or n in ("PRESSURE", "SWAT", "SGAS", "RS")]
    compared = 0
    for index, (report, get) in enumerate(steps):
        grid = fetch(reader, times[index])
        field = grid.GetFieldData()
        if field.GetArray("ReportStep").GetValue(0) != report:
            rt.fail(f"{name}: time {times[index]} shows report {field.GetArray('ReportStep').GetValue(0)},"
                    f" expected {report}")
        for array_name in dynamic:
            if grid.GetCellData().GetArray(array_name) is None:
                continue
            compare_cells(name, f"report {report} {array_name}", eclipse_order(grid, array_name, dims),
                          get(array_name), active)
            compared += 1
        if "SOIL" not in restart_names and grid.GetCellData().GetArray("SOIL") is not None:
            # Derived for restarts without SOIL: 1 - SWAT - SGAS (SGAS absent: two phases).
            water = np.asarray(get("SWAT"), np.float32)
            gas = np.asarray(get("SGAS"), np.float32) if "SGAS" in restart_names else 0.0
            expected = np.float32(1.0) - water - gas
            compare_cells(name, f"report {report} derived SOIL", eclipse_order(grid, "SOIL", dims),
                          expected, active)
            compared += 1
    if compared < len(steps):
        rt.fail(f"{name}: only {compared} restart arrays compared over {len(steps)} steps")
    print(f"{name}: {checked} INIT arrays and {compared} restart arrays over {len(steps)} report"
          f" steps equal OPM's; times {times[0]} .. {times[-1]} days")
    return times


times = {}
for model_name, model_path in MODELS.items():
    times[model_name] = check_model(model_name, model_path)

# Times: Brugge's restarts are 30 days apart from day 0; SPE9's 90 steps end at day 900.
if times["Brugge"] != [30.0 * s for s in range(11)]:
    rt.fail(f"Brugge times {times['Brugge']}")
if len(times["SPE9"]) != 90 or times["SPE9"][-1] != 900.0:
    rt.fail(f"SPE9: {len(times['SPE9'])} steps ending at {times['SPE9'][-1]}")
print("EGRID reader agrees with OPM EclIO")
