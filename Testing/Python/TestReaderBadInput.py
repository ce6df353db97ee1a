"""Bad input through the GRDECLReader proxy: each case logs one clear error naming the file,
line and keyword, and leaves the outputs empty; the reader then recovers on a good file."""
import os
import tempfile

from paraview import servermanager

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
work = tempfile.mkdtemp(prefix="resmr-bad-", dir=args.temp)
GOOD = """SPECGRID
 2 1 1 1 F /
COORD
 0 0 0 0 0 10  1 0 0 1 0 10  2 0 0 2 0 10
 0 1 0 0 1 10  1 1 0 1 1 10  2 1 0 2 1 10 /
ZCORN
 8*100 8*101 /
"""
CASES = {
    "truncated.grdecl": (GOOD[: GOOD.index("ZCORN") + 14], ["truncated.grdecl", "ZCORN", "end of file"]),
    "count.grdecl": (GOOD + "PORO\n 0.1 0.2 0.3 /\n", ["count.grdecl:9", "PORO", "too many"]),
    "include.DATA": ("INCLUDE\n 'nowhere.inc' /\n", ["include.DATA:1", "INCLUDE", "nowhere.inc"]),
    "garbage.grdecl": (GOOD.replace("8*101", "8*101 @@@"), ["garbage.grdecl:7", "ZCORN", "@@@"]),
    "nan.grdecl": (GOOD.replace("2 1 0 2 1 10 /", "2 1 0 2 NaN 10 /"), ["nan.grdecl:5", "COORD", "NaN"]),
    "dims.grdecl": ("SPECGRID\n 99999 99999 99999 1 F /\n", ["dims.grdecl:1", "SPECGRID", "larger"]),
    "negative.grdecl": ("SPECGRID\n -2 1 1 1 F /\n", ["negative.grdecl:1", "SPECGRID"]),
    "unterminated.grdecl": (GOOD.replace("8*101 /", "8*101\nPORO\n 1 2 /"), ["unterminated.grdecl:8", "ZCORN", "missing '/'"]),
    "binary.bgrdecl": (b"\x00\x00\x00\x10SPECGRID\x00\x00\x00\x04INTE\x00\x00\x00\x10\x00\x00\x00\x10\x00\x00", ["binary.bgrdecl", "SPECGRID", "truncated"]),
}

from paraview import simple
for name, (content, fragments) in CASES.items():
    path = os.path.join(work, name)
    with open(path, "wb") as handle:
        handle.write(content if isinstance(content, bytes) else content.encode())
    rt.expect_read_error(simple.GRDECLReader(FileName=path), name, fragments)

# The same reader object recovers when pointed at a good file.
good = os.path.join(work, "good.grdecl")
with open(good, "w") as handle:
    handle.write(GOOD + "PORO\n 0.1 0.2 /\n")
reader = simple.GRDECLReader(FileName=os.path.join(work, "count.grdecl"))
reader.UpdatePipeline()
reader.FileName = good
reader.UpdatePipeline()
grid = servermanager.Fetch(reader, arg1=None, arg2=None, idx=0)
if grid.GetNumberOfCells() != 2 or grid.GetCellData().GetArray("PORO") is None:
    rt.fail("reader did not recover after an error")
print("PASS")
