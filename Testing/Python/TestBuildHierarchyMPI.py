"""Two MPI ranks build the multiresolution file that one process builds (paper Sec. 4.2: the
diamonds of a level are independent; ranks through ParaView's own MPI). The ranks build level
by level, the one process depth first: the same regions either way.

Run as: mpirun -np 2 pvbatch --symmetric TestBuildHierarchyMPI.py --plugin P --temp T --resmr R
Both ranks run the BuildMultiresolutionHierarchy proxy with the same properties; rank 0 then
checks the file whole (every level and region present once, the finest level holding every
active cell of the model, a coarse level read back through the plugin) and, with --reference
one-process, compares it region by region (level, index, counts, errors, bounds and the CRC of
every chunk, which pins the decoded meshes) with `resmr build` of the same model in one process.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import time

from paraview import simple
from vtkmodules.vtkParallelCore import vtkMultiProcessController

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", required=True)
parser.add_argument("--temp", required=True)
parser.add_argument("--resmr", required=True)
parser.add_argument("--model", default="synth:90x70x12:5",
                    help="the input both builds read (the test's is small; bigger ones check the scale)")
parser.add_argument("--cmax", type=int, default=64)
parser.add_argument("--threads", type=int, default=1, help="worker threads of each rank")
parser.add_argument("--single-threads", type=int, default=0, help="worker threads of the one process (0: --threads)")
parser.add_argument("--reference", choices=("one-process", "none"), default="one-process",
                    help="none: the whole-file checks only (a second build of a big model doubles the time)")
parser.add_argument("--active", type=int, default=0, help="active cells of the model, when known (0: not checked)")
args = parser.parse_args()

controller = vtkMultiProcessController.GetGlobalController()
rank = controller.GetLocalProcessId()
ranks = controller.GetNumberOfProcesses()
if ranks != 2:
    print(f"FAIL: expected 2 MPI ranks, got {ranks}")
    sys.exit(1)
os.makedirs(args.temp, exist_ok=True)
controller.Barrier()
simple.LoadPlugin(args.plugin, remote=False, ns=vars(simple))

model = args.model
parallel = os.path.join(args.temp, "two-ranks.resmr")
single = os.path.join(args.temp, "one-process.resmr")
if rank == 0:
    for path in (parallel, single):
        if os.path.exists(path):
            os.remove(path)
controller.Barrier()

started = time.time()
build = simple.BuildMultiresolutionHierarchy(Input=model, FileName=parallel, Cmax=args.cmax, Threads=args.threads)
build.UpdatePipeline()
build.UpdatePropertyInformation()
error = build.GetPropertyValue("LastError")
if error:
    print(f"FAIL: rank {rank}: {error}")
    sys.exit(1)
controller.Barrier()
parallel_seconds = time.time() - started


def info(path):
    text = subprocess.run([args.resmr, "info", "--regions", path], check=True, capture_output=True, text=True).stdout
    return json.loads(text)


def model_active_cells():
    """Active cells of the model: --active, or for a small synthetic model the generator's own
    count (`resmr synth` writes it out in a moment); 0 when neither is at hand."""
    match = re.fullmatch(r"synth:(\d+)x(\d+)x(\d+)(?::(\d+))?", model)
    if args.active or not match or int(match[1]) * int(match[2]) * int(match[3]) > 10_000_000:
        return args.active
    grid = os.path.join(args.temp, "model.EGRID")
    summary = subprocess.run([args.resmr, "synth", match[1], match[2], match[3], "--seed", match[4] or "1", "-o",
                              grid, "--quiet"], check=True, capture_output=True, text=True).stdout
    return json.loads(summary)["active"]


def check_whole(a):
    """The two-rank file on its own: every level complete, every region once, every active cell."""
    failures = []
    active = model_active_cells()
    regions = a["region_list"]
    if len(regions) < 20 or a["leaf_level"] < 3:
        failures.append(f"too small a hierarchy to test: {len(regions)} regions, leaf level {a['leaf_level']}")
    levels = a["levels"]
    if [level["level"] for level in levels] != list(range(a["leaf_level"] + 1)):
        failures.append(f"levels {[level['level'] for level in levels]} are not 0..{a['leaf_level']}")
    if len(regions) != a["regions"] or sum(level["regions"] for level in levels) != a["regions"]:
        failures.append(f"{len(regions)} region records, {a['regions']} in the header, "
                        f"{sum(level['regions'] for level in levels)} over the levels")
    keys = {(r[0], r[1]) for r in regions}
    if len(keys) != len(regions):
        failures.append(f"{len(regions) - len(keys)} regions written twice")
    for level in levels:
        held = [r for r in regions if r[0] == level["level"]]
        if len(held) != level["regions"] or any(r[3] <= 0 for r in held):
            failures.append(f"level {level['level']}: {len(held)} records for {level['regions']} regions, "
                            f"{sum(r[3] <= 0 for r in held)} of no cells")
    if active and levels[-1]["active_cells"] != active:
        failures.append(f"the finest level holds {levels[-1]['active_cells']} active cells, the model {active}")
    # Chunks of both ranks, read back and decoded through the plugin: the finest level of a
    # small model, a coarse one of a big model (its finest would not fit in memory).
    read = a["leaf_level"] if a["cells"] <= 10_000_000 else min(3, a["leaf_level"])
    extract = simple.ExtractMultiresolutionLevel(FileName=parallel, Level=read)
    extract.UpdatePipeline()
    cells = extract.GetDataInformation().GetNumberOfCells()  # every cell of the level's columns
    if cells != levels[read]["columns"] * a["dims"][2]:
        failures.append(f"level {read} of the two-rank file reads {cells} cells, its record says "
                        f"{levels[read]['columns']} columns of {a['dims'][2]}")
    return failures


def compare_with_one_process(a):
    """`resmr build` of the same model in one process, then the two files region by region."""
    failures = []
    started = time.time()
    subprocess.run([args.resmr, "build", model, "-o", single, "--cmax", str(args.cmax), "--threads",
                    str(args.single_threads or args.threads), "--quiet"], check=True, stdout=subprocess.DEVNULL)
    print(f"one process: {time.time() - started:.1f} s")
    b = info(single)
    for key in ("dims", "leaf_level", "cmax", "regions", "levels", "hash", "geometry_id", "bytes"):
        if a[key] != b[key]:
            failures.append(f"{key} differs: two ranks {a[key]}, one process {b[key]}")
    if a["region_list"] != b["region_list"]:
        differ = [x for x, y in zip(a["region_list"], b["region_list"]) if x != y]
        failures.append(f"{len(differ)} region records differ, first: {differ[:2]}")
    return failures


def check_file():
    print(f"two ranks: {parallel_seconds:.1f} s")
    a = info(parallel)
    failures = check_whole(a)
    if args.reference == "one-process":
        failures += compare_with_one_process(a)
    for failure in failures:
        print("FAIL: " + failure)
    if not failures:
        print(f"MPI build {'equivalent' if args.reference == 'one-process' else 'whole'}: "
              f"{len(a['region_list'])} regions, {a['leaf_level'] + 1} levels, {a['hash']['cells']} hashed cells, "
              f"geometry {a['geometry_id']}")
    if not failures and a["cells"] > 10_000_000:
        for path in (parallel, single):  # large: nothing to look at afterwards
            if os.path.exists(path):
                os.remove(path)
    return bool(failures)


# Rank 1 waits for rank 0's checks (and one-process build) on a file, sleeping: an MPI
# barrier polls, and its busy core would take one of the two the one-process build runs on.
finished = os.path.join(args.temp, "rank0-finished")
if rank == 0 and os.path.exists(finished):
    os.remove(finished)
controller.Barrier()
failed = False
if rank == 0:
    try:
        failed = check_file()
    finally:
        with open(finished, "w") as marker:
            marker.write("done")
else:
    while not os.path.exists(finished):
        time.sleep(1)
controller.Barrier()
# On success the script just ends: pvbatch then finalizes MPI and mpirun exits 0. sys.exit()
# leaves without MPI_Finalize, which mpirun reports as a rank "exiting improperly" with a
# non-zero status, as wanted on failure.
if failed:
    sys.exit(1)
