"""Decks as other tools write them open, and open right: every class of edit and keyword the
viewer applies or skips (EQUALS, MULTIPLY, COPY, MINVALUE, MAXVALUE, OPERATE,
COPYREG, MULTFLT, MULTREGT, MULTREGP, EDITNNC, NNC, MINPV, PINCH, CARFIN ...
ENDFIN, AQUNUM/AQUCON, THPRES, BOX edits of multipliers, edits of TRANX/PORV/MULTPV) inserted
into the GRID, EDIT, PROPS, REGIONS and SOLUTION sections of copies of Reek's and SPE9's decks
made here. GRDECLReader, `resmr info` and `resmr build` open them; the corners and every
edited array equal OPM's EclipseState (python3-opm-common) on the same deck, and each skipped
keyword gives exactly one warning naming the file, the line, the keyword and the array.
A missing INCLUDE in SOLUTION is a warning; one that held the grid is an error naming it.
COPYBOX, EQUALREG, MULTIREG, ADDREG and OPERATER are checked value for value in Core.GrdeclParser
only: Debian 12's OPM (2022.10) leaves the arrays they edit as they were."""
import json
import os
import shutil
import subprocess
import tempfile

import numpy as np
from opm.io.ecl_state import EclipseState

import resmr_testing as rt
from opm_testing import corner_error, opm_corners, opm_deck, our_corners

args = rt.arguments()
rt.load_plugin(args.plugin)
DATA = args.data
RESMR = os.environ["RESMR_EXECUTABLE"]
work = tempfile.mkdtemp(prefix="resmr-deck-edits-", dir=args.temp)
MILLIDARCY = 9.869232667160130e-16  # OPM gives permeabilities in m2
NEXT_SECTION = {"RUNSPEC": "GRID", "GRID": "EDIT", "EDIT": "PROPS", "PROPS": "REGIONS",
                "REGIONS": "SOLUTION", "SOLUTION": "SUMMARY"}

# (section, text, [(keyword, array or None, the line of the block the warning names)])
GRID_EDITS = [
    ("GRID", "EQUALS\n 'MULTNUM' 1 /\n 'MULTNUM' 2 11 40 1 64 1 14 /\n 'OPERNUM' 1 /\n/\n", []),
    ("GRID", "MULTREGT\n 1 2 0.5 XYZ 'ALL' M /\n/\n", [("MULTREGT", None, 0)]),
    ("GRID", "NNC\n 1 1 1 2 1 1 0.5 /\n/\n", [("NNC", None, 0)]),
    ("GRID", "MINPV\n 1e-6 /\n", [("MINPV", None, 0)]),
    ("GRID", "EQUALS\n 'MULTX' 0.5 1 10 1 10 1 1 /\n/\n", [("EQUALS", "MULTX", 1)]),
    ("GRID", "MULTIPLY\n 'MULTY' 2 /\n/\n", [("MULTIPLY", "MULTY", 1)]),
    ("GRID", "BOX\n 1 5 1 5 1 1 /\nMULTZ\n 25*0.1 /\nENDBOX\n", [("MULTZ", "MULTZ", 2)]),
    ("GRID", "MINVALUE\n 'PERMX' 5 /\n/\nMAXVALUE\n 'PORO' 0.3 /\n/\n", []),
    ("GRID", "OPERATE\n 'PERMY' 1* 1* 1* 1* 1* 1* MULTX 'PERMX' 0.5 /\n"
             " 'PERMZ' 1 10 1 10 1 2 MULTA 'PERMX' 0.1 2 /\n/\n", []),
    ("GRID", "CARFIN\n 'LGR1' 1 2 1 2 1 1 4 4 1 /\nENDFIN\n", [("CARFIN", "'LGR1'", 0)]),
    ("GRID", "AQUNUM\n 1 1 1 1 1e6 1e3 0.3 100 2000 200 1 1 /\n/\n"
             "AQUCON\n 1 1 1 1 1 1 1 'I-' /\n/\n", [("AQUNUM", None, 0), ("AQUCON", None, 3)]),
    ("EDIT", "MULTIPLY\n 'TRANX' 0.5 /\n 'TRANY' 0.5 1 10 1 10 1 1 /\n/\n",
     [("MULTIPLY", "TRANX", 1), ("MULTIPLY", "TRANY", 2)]),
    ("EDIT", "EQUALS\n 'PORV' 1000 1 1 1 1 1 1 /\n/\n", [("EQUALS", "PORV", 1)]),
    ("EDIT", "MULTREGP\n 1 0.5 M /\n/\nEDITNNC\n 1 1 1 2 1 1 0.5 /\n/\n",
     [("MULTREGP", None, 0), ("EDITNNC", None, 3)]),
    ("PROPS", "MULTIPLY\n 'MULTPV' 0.5 /\n/\n", [("MULTIPLY", "MULTPV", 1)]),
    ("REGIONS", "COPYREG\n 'FIPNUM' 'PVTNUM' 2 M /\n/\n", []),
    ("SOLUTION", "THPRES\n 1 2 1* /\n/\n", [("THPRES", None, 0)]),
]
RUNSPEC = "AQUDIMS\n 1 1 1* 1* 1* 1* 1* 1* /\nLGR\n 1 100 /\n"


def copy_deck(source, name, includes, blocks, extra_sections=()):
    """The deck `source` with `blocks` inserted at the end of their sections, written beside
    links to its include files; returns (path, expected warnings as (keyword, array, line))."""
    folder = os.path.join(work, name)
    os.makedirs(folder)
    for link, target in includes.items():
        os.symlink(target, os.path.join(folder, link))
    with open(source) as handle:
        text = handle.read()
    for section in extra_sections:  # sections the deck lacks, empty, before their successor
        text = text.replace(f"\n{NEXT_SECTION[section]}\n", f"\n{section}\n\n{NEXT_SECTION[section]}\n", 1)
    text = text.replace("\nGRID\n", "\n" + RUNSPEC + "GRID\n", 1)
    for section, block, _ in blocks:
        start = text.index(f"\n{section}\n")
        end = text.index(f"\n{NEXT_SECTION[section]}\n", start + 1)
        text = text[:end] + "\n" + block + text[end:]
    expected = []
    for _, block, warnings in blocks:
        first_line = text[:text.index(block)].count("\n") + 1
        expected += [(keyword, array, first_line + offset) for keyword, array, offset in warnings]
    path = os.path.join(folder, "EDITED.DATA")
    with open(path, "w") as handle:
        handle.write(text)
    return path, expected


def warnings_of(reader):
    reader.UpdatePropertyInformation()
    return [line for line in reader.GetPropertyValue("Warnings").split("\n") if line]


def check_warnings(name, path, warnings, baseline, expected):
    """Every expected warning exactly once, and nothing else beyond the unedited deck's."""
    for keyword, array, line in expected:
        place = f"{os.path.basename(path)}:{line}: keyword {keyword}"
        hits = [w for w in warnings if place in w and (array is None or array in w)]
        if len(hits) != 1:
            rt.fail(f"{name}: {len(hits)} warnings for {keyword} {array or ''} at line {line}"
                    f" (expected 1): {warnings}")
    if len(warnings) != len(baseline) + len(expected):
        rt.fail(f"{name}: {len(warnings)} warnings, expected {len(baseline)} of the unedited deck"
                f" and {len(expected)} for the edits: {warnings}")
    print(f"{name}: {len(expected)} warnings for the inserted keywords, each naming its line")


def check_against_opm(name, path, dims, arrays, integer_arrays):
    nx, ny, nz = dims
    reader, grid = rt.read_grid(path, ApplyMapAxes=0, ShowInactiveCells=1)
    if reader.GetPropertyValue("LastError"):
        rt.fail(f"{name}: GRDECLReader failed: {reader.GetPropertyValue('LastError')}")
    deck = opm_deck(path)
    state = EclipseState(deck)
    reference = opm_corners(deck, dims, name, work)
    ours, _ = our_corners(grid, dims)
    error, tolerance = corner_error(ours, reference)
    if np.any(error > tolerance):
        rt.fail(f"{name}: corners differ from OPM by {error} (tolerance {tolerance})")
    # OPM's active cells, in order, named by a ROCKNUM of global index + 1 (inserted).
    props = state.field_props()
    opm_cells = np.asarray(props.get_int_array("ROCKNUM")) - 1
    eclipse_cell = ((rt.cell_array(grid, "K") - 1) * ny + rt.cell_array(grid, "J") - 1) * nx + \
        rt.cell_array(grid, "I") - 1
    ours_by_cell = {}
    for array in arrays + integer_arrays:
        values = np.full(nx * ny * nz, np.nan)
        values[eclipse_cell] = rt.cell_array(grid, array)
        ours_by_cell[array] = values[opm_cells]
    actnum = np.zeros(nx * ny * nz)
    actnum[eclipse_cell] = rt.cell_array(grid, "ACTNUM") if grid.GetCellData().GetArray("ACTNUM") \
        else 1
    if np.any(actnum[opm_cells] == 0):
        rt.fail(f"{name}: cells OPM keeps active are inactive here")
    # The numerical aquifer's cell (1, 1, 1): OPM gives it the aquifer's PORO and PERM, the
    # viewer the grid's (and says so).
    compared = opm_cells != 0
    for array in arrays:
        theirs = np.asarray(props.get_double_array(array))[compared]
        if array.startswith("PERM"):
            theirs = theirs / MILLIDARCY
        worst = np.abs(ours_by_cell[array][compared] - theirs).max() / max(np.abs(theirs).max(), 1e-300)
        if not worst <= 1e-12:
            rt.fail(f"{name}: {array} differs from OPM (worst relative {worst:.3g})")
    for array in integer_arrays:
        theirs = np.asarray(props.get_int_array(array), np.float64)
        differing = int((ours_by_cell[array] != theirs).sum())
        if differing:
            rt.fail(f"{name}: {array} differs from OPM in {differing} cells")
    print(f"{name}: corners and {len(arrays) + len(integer_arrays)} arrays equal OPM's on its"
          f" {opm_cells.size} active cells ({int((actnum > 0).sum())} with ACTNUM here)")
    return reader


def check_tools(name, path, reader_warnings):
    """resmr info and resmr build (the bounded-memory parse) open the deck with the same
    warnings as the reader."""
    info = subprocess.run([RESMR, "info", path], capture_output=True, text=True)
    if info.returncode != 0:
        rt.fail(f"{name}: resmr info failed: {info.stderr}")
    output = os.path.join(work, name + ".resmr")
    build = subprocess.run([RESMR, "build", path, "-o", output, "--quiet"], capture_output=True,
                           text=True)
    if build.returncode != 0 or not os.path.getsize(output):
        rt.fail(f"{name}: resmr build failed: {build.stderr}")
    for run, tool in ((info, "info"), (build, "build")):
        printed = [line[len("resmr: warning: "):] for line in run.stderr.splitlines()
                   if line.startswith("resmr: warning: ")]
        if printed != reader_warnings:
            rt.fail(f"{name}: resmr {tool} warnings differ from the reader's: {printed}")
    print(f"{name}: resmr info ({json.loads(info.stdout)['active']} active) and resmr build"
          f" open it with the reader's {len(reader_warnings)} warnings")


def marker(cells):
    return ("REGIONS", "ROCKNUM\n" + "\n".join(
        " ".join(str(c + 1) for c in range(row, min(row + 20, cells)))
        for row in range(0, cells, 20)) + " /\n", [])


# Reek: the deck and its include folder.
reek_model = os.path.join(DATA, "reek/res2df_sim/eclipse/model")
reek_source = os.path.join(reek_model, "2_R001_REEK-0.DATA")
reek_blocks = GRID_EDITS + [marker(40 * 64 * 14),
                            ("GRID", "MULTFLT\n 'F1' 0.5 /\n/\n", [("MULTFLT", None, 0)]),
                            ("PROPS", "MINVALUE\n 'SWL' 0.05 /\n/\nMAXVALUE\n 'SWL' 0.5 /\n/\n", [])]
reek_path, reek_expected = copy_deck(
    reek_source, "reek/model", {}, reek_blocks)
os.symlink(os.path.join(DATA, "reek/res2df_sim/eclipse/include"), os.path.join(work, "reek/include"))
baseline_reader, _ = rt.read_grid(reek_source)
reek_reader = check_against_opm(
    "Reek", reek_path, (40, 64, 14), ["PORO", "PERMX", "PERMY", "PERMZ", "SWL", "SWCR", "SGU"],
    ["SATNUM", "FIPNUM", "EQLNUM", "PVTNUM", "MULTNUM"])
reek_warnings = warnings_of(reek_reader)
check_warnings("Reek", reek_path, reek_warnings, warnings_of(baseline_reader), reek_expected)
check_tools("Reek", reek_path, reek_warnings)

# SPE9, corner-point: a GRID, PROPS and SOLUTION deck; EDIT and REGIONS are added.
spe9_folder = os.path.join(DATA, "spe9/opm-data_deck")
spe9_source = os.path.join(spe9_folder, "SPE9_CP.DATA")
spe9_includes = {name: os.path.join(spe9_folder, name) for name in ("SPE9.GRDECL", "PERMVALUES.DATA")}
# SPE9's deck gives no FIPNUM, and OPM 2024.10 (Debian 13) refuses a COPYREG from an array the
# deck does not give (OPM 2022.10 copies the default 1): FIPNUM is given first, in two regions,
# so that the copy moves values that differ.
SPE9_FIPNUM = ("REGIONS", "EQUALS\n 'FIPNUM' 1 /\n 'FIPNUM' 3 1 12 1 25 1 15 /\n/\n", [])
spe9_blocks = [(section, block.replace(" 11 40 1 64 1 14 ", " 11 24 1 25 1 15 "), warnings)
               for section, block, warnings in GRID_EDITS] + [marker(24 * 25 * 15)]
spe9_blocks.insert(next(i for i, (_, block, _) in enumerate(spe9_blocks) if block.startswith("COPYREG")),
                   SPE9_FIPNUM)
spe9_path, spe9_expected = copy_deck(
    spe9_source, "spe9", spe9_includes, spe9_blocks, extra_sections=("EDIT", "REGIONS"))
spe9_reader = check_against_opm(
    "SPE9_CP", spe9_path, (24, 25, 15), ["PORO", "PERMX", "PERMY", "PERMZ"],
    ["FIPNUM", "PVTNUM", "MULTNUM"])
spe9_warnings = warnings_of(spe9_reader)
check_warnings("SPE9_CP", spe9_path, spe9_warnings, warnings_of(rt.read_grid(spe9_source)[0]),
               spe9_expected)
check_tools("SPE9_CP", spe9_path, spe9_warnings)

# A SOLUTION include that was not shipped: a warning, the grid opens.
unshipped_path, _ = copy_deck(spe9_source, "spe9_unshipped", spe9_includes, [
    ("SOLUTION", "INCLUDE\n 'INITIAL_STATE_NOT_SHIPPED.INC' /\n", [])])
reader, grid = rt.read_grid(unshipped_path)
unshipped = [w for w in warnings_of(reader) if "INITIAL_STATE_NOT_SHIPPED.INC" in w and "not found" in w]
if reader.GetPropertyValue("LastError") or grid.GetNumberOfCells() != 9000 or len(unshipped) != 1:
    rt.fail(f"SPE9 with an unshipped SOLUTION include: error "
            f"'{reader.GetPropertyValue('LastError')}', {grid.GetNumberOfCells()} cells, warnings"
            f" {warnings_of(reader)}")
check_tools("SPE9 unshipped include", unshipped_path, warnings_of(reader))

# The grid's own include missing: an error naming that include.
missing_grid = os.path.join(work, "spe9_no_grid")
shutil.copytree(os.path.join(work, "spe9_unshipped"), missing_grid, symlinks=True)
os.remove(os.path.join(missing_grid, "SPE9.GRDECL"))
rt.expect_read_error(rt.read_grid(os.path.join(missing_grid, "EDITED.DATA"))[0], "SPE9 without grid",
                     ["EDITED.DATA", "SPE9.GRDECL", "not found"])
info = subprocess.run([RESMR, "info", os.path.join(missing_grid, "EDITED.DATA")],
                      capture_output=True, text=True)
if info.returncode == 0 or "SPE9.GRDECL" not in info.stderr:
    rt.fail(f"resmr info on a deck without its grid include: {info.returncode} {info.stderr}")
print("PASS")
