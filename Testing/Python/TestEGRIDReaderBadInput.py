"""Bad simulator output through the EGRIDReader proxy. Corrupt files (truncated records,
record markers that disagree, counts larger than the file, unknown types, old GRID files)
give one clear error naming the file and keyword and an empty output; restarts of another
grid and missing companions give warnings naming the file, and the grid is still shown.
An empty, bit-flipped or foreign INIT gives a warning and no static arrays, the steps stay; a
restart cut short offers its complete steps and names the one left out (file, step, byte);
a damaged data block met only when an array is read costs that array, with a warning. The
reader then recovers on a good file."""
import os
import shutil
import struct
import tempfile

from paraview import servermanager, simple

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
work = tempfile.mkdtemp(prefix="resmr-bad-egrid-", dir=args.temp)
EIGHT = os.path.join(args.data, "format_variants/res2df_eightcells/EIGHTCELLS")
with open(EIGHT + ".EGRID", "rb") as handle:
    GOOD = handle.read()


def header_offset(data, keyword):
    """Byte offset of the 16-byte header record of `keyword` in an unformatted file."""
    offset = data.index(keyword.ljust(8).encode()) - 4
    assert struct.unpack(">i", data[offset:offset + 4])[0] == 16
    return offset


zcorn = header_offset(GOOD, "ZCORN")
zcorn_data = zcorn + 24
coord = header_offset(GOOD, "COORD")


def with_bytes(data, offset, new):
    return data[:offset] + new + data[offset + len(new):]


first_length = struct.unpack(">i", GOOD[zcorn_data:zcorn_data + 4])[0]
CORRUPT = {
    "truncated.EGRID": (GOOD[: zcorn_data + 100], ["truncated.EGRID", "ZCORN", "too short"]),
    "markers.EGRID": (with_bytes(GOOD, zcorn_data + 4 + first_length, struct.pack(">i", first_length - 4)),
                      ["markers.EGRID", "ZCORN", "marker"]),
    "count.EGRID": (with_bytes(GOOD, zcorn + 12, struct.pack(">i", 10**8)),
                    ["count.EGRID", "ZCORN", "too short"]),
    "type.EGRID": (with_bytes(GOOD, coord + 16, b"QUAD"), ["type.EGRID", "COORD", "unknown data type 'QUAD'"]),
    "garbage.EGRID": (b"\x00\x00\x00\x10" + b"\xff" * 100, ["garbage.EGRID"]),
}
for name, (content, fragments) in CORRUPT.items():
    path = os.path.join(work, name)
    with open(path, "wb") as handle:
        handle.write(content)
    rt.expect_read_error(simple.EGRIDReader(FileName=path), name, fragments)

# Old-style GRID files are refused by name.
old = os.path.join(args.data, "format_variants/xtgeo_simpleb8/E100_BO.GRID")
reader = simple.OpenDataFile(old)
if reader is None or reader.GetXMLName() != "EGRIDReader":
    rt.fail("old GRID file: not offered to the EGRIDReader")
reader.UpdatePipeline()
reader.UpdatePropertyInformation()
if "old-style GRID" not in reader.GetPropertyValue("LastError"):
    rt.fail(f"old GRID file: {reader.GetPropertyValue('LastError')!r}")
print(f"E100_BO.GRID: error reported: {reader.GetPropertyValue('LastError')}")
simple.Delete(reader)


def open_with_warnings(path, fragments):
    reader = simple.EGRIDReader(FileName=path)
    reader.UpdatePipeline()
    grid = servermanager.Fetch(reader, arg1=None, arg2=None, idx=0)
    reader.UpdatePropertyInformation()
    if reader.GetPropertyValue("LastError"):
        rt.fail(f"{path}: unexpected error {reader.GetPropertyValue('LastError')}")
    warnings = reader.GetPropertyValue("Warnings")
    missing = [f for f in fragments if f not in warnings]
    if missing:
        rt.fail(f"{path}: warnings lack {missing}: {warnings!r}")
    if grid.GetCells().GetNumberOfCells() != 8:
        rt.fail(f"{path}: grid not shown")
    print(f"{os.path.basename(path)}: grid shown, warned: {warnings.strip()}")
    return reader, grid


# Missing companions: the grid alone.
alone = os.path.join(work, "ALONE.EGRID")
shutil.copy(EIGHT + ".EGRID", alone)
reader, grid = open_with_warnings(alone, ["ALONE.EGRID", "no INIT file", "no restart files"])
if list(reader.TimestepValues):
    rt.fail("grid alone: has time steps")
simple.Delete(reader)

# A restart of another grid (SPE1, 300 cells) beside the 8-cell grid: refused per step.
other = os.path.join(work, "OTHER.EGRID")
shutil.copy(EIGHT + ".EGRID", other)
shutil.copy(EIGHT + ".INIT", os.path.join(work, "OTHER.INIT"))
shutil.copy(os.path.join(args.data, "format_variants/resdata_simple/SIMPLE.UNRST"),
            os.path.join(work, "OTHER.UNRST"))
reader, grid = open_with_warnings(other, ["OTHER.UNRST", "INTEHEAD", "does not belong to the grid"])
if grid.GetCellData().GetArray("PRESSURE") is not None:
    rt.fail("restart of another grid: its PRESSURE is shown")
if grid.GetCellData().GetArray("PORO") is None:
    rt.fail("restart of another grid: the INIT arrays are lost too")

# Damaged INITs: the grid and the restart steps are shown, no static array, a warning.
with open(EIGHT + ".INIT", "rb") as handle:
    INIT = handle.read()
third = header_offset(INIT, "DOUBHEAD")
BAD_INITS = {
    "EMPTYINIT": (b"", ["EMPTYINIT.INIT", "the file is empty"]),
    "FLIPPEDINIT": (with_bytes(INIT, third + 3, bytes([INIT[third + 3] ^ 0x02])),
                    ["FLIPPEDINIT.INIT", f"damaged or cut short at byte {third}"]),
    "FOREIGNINIT": (open(os.path.join(args.data, "spe1/resdata_rft/SPE1.INIT"), "rb").read(),
                    ["FOREIGNINIT.INIT", "does not belong to this grid"]),
}
for stem, (content, fragments) in BAD_INITS.items():
    base = os.path.join(work, stem)
    shutil.copy(EIGHT + ".EGRID", base + ".EGRID")
    shutil.copy(EIGHT + ".UNRST", base + ".UNRST")
    with open(base + ".INIT", "wb") as handle:
        handle.write(content)
    reader, grid = open_with_warnings(base + ".EGRID", fragments)
    if grid.GetCellData().GetArray("PORO") is not None:
        rt.fail(f"{stem}: static arrays shown from a bad INIT")
    if len(reader.TimestepValues) != 3 or grid.GetCellData().GetArray("PRESSURE") is None:
        rt.fail(f"{stem}: the restart steps are lost too")
    simple.Delete(reader)

# A restart cut inside its third step: two steps, the third named with its byte offset; and
# a data block marker damaged inside the second step's SWAT: the array is left out with a
# warning when that step is shown, the rest of the step is.
with open(EIGHT + ".UNRST", "rb") as handle:
    UNRST = handle.read()
seqnums = [i - 4 for i in range(len(UNRST)) if UNRST.startswith(b"SEQNUM  ", i)]
base = os.path.join(work, "CUTRUN")
shutil.copy(EIGHT + ".EGRID", base + ".EGRID")
shutil.copy(EIGHT + ".INIT", base + ".INIT")
with open(base + ".UNRST", "wb") as handle:
    handle.write(UNRST[: seqnums[2] + 500])
reader, grid = open_with_warnings(base + ".EGRID", ["CUTRUN.UNRST", "report step 2 left out: incomplete at byte"])
if len(reader.TimestepValues) != 2:
    rt.fail(f"cut restart: {len(reader.TimestepValues)} steps offered, expected 2")
simple.Delete(reader)
swat = UNRST.index(b"SWAT    ", seqnums[1]) - 4
marker = swat + 24
base = os.path.join(work, "BLOCKRUN")
shutil.copy(EIGHT + ".EGRID", base + ".EGRID")
shutil.copy(EIGHT + ".INIT", base + ".INIT")
with open(base + ".UNRST", "wb") as handle:
    # The end marker of SWAT's data block: indexing checks only the first marker.
    handle.write(with_bytes(UNRST, marker + 4 + 32, struct.pack(">i", 33)))
reader, grid = open_with_warnings(base + ".EGRID", [])
times = list(reader.TimestepValues)
reader.UpdatePipeline(times[1])
grid = servermanager.Fetch(reader, arg1=None, arg2=None, idx=0)
reader.UpdatePropertyInformation()
warnings = reader.GetPropertyValue("Warnings")
if reader.GetPropertyValue("LastError") or grid.GetCellData().GetArray("PRESSURE") is None:
    rt.fail(f"damaged SWAT block: the step failed: {reader.GetPropertyValue('LastError')}")
if grid.GetCellData().GetArray("SWAT") is not None or "SWAT is not shown" not in warnings:
    rt.fail(f"damaged SWAT block: SWAT shown or not warned: {warnings!r}")
print(f"BLOCKRUN: step 2 shown without SWAT, warned: {warnings.strip().splitlines()[-1]}")
simple.Delete(reader)

# The same reader recovers on a good file.
reader.FileName = EIGHT + ".EGRID"
reader.UpdatePipeline()
grid = servermanager.Fetch(reader, arg1=None, arg2=None, idx=0)
reader.UpdatePropertyInformation()
if reader.GetPropertyValue("LastError") or grid.GetCellData().GetArray("PRESSURE") is None:
    rt.fail("reader did not recover on EIGHTCELLS.EGRID")
print("bad simulator output is reported clearly; the reader recovers")
