"""Two MPI ranks build the multiresolution file that one process builds (paper Sec. 4.2: the
diamonds of a level are independent; ranks through ParaView's own MPI). The ranks build level
by level, the one process depth first: the same regions either way.

Run as: mpirun -np 2 pvbatch --symmetric TestBuildHierarchyMPI.py --plugin P --temp T --resmr R
Both ranks run the BuildMultiresolutionHierarchy proxy with the same properties; rank 0 then
compares the file, region by region (level, index, counts, errors, bounds and the CRC of every
chunk, which pins the decoded meshes), with `resmr build` of the same model in one process.
"""
import argparse
import json
import os
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


def build_one_process_and_compare():
    """Rank 0: `resmr build` of the same model in one process, then the two files region by region."""
    failed = False
    started = time.time()
    subprocess.run([args.resmr, "build", model, "-o", single, "--cmax", str(args.cmax), "--threads",
                    str(args.single_threads or args.threads), "--quiet"], check=True, stdout=subprocess.DEVNULL)
    print(f"two ranks: {parallel_seconds:.1f} s; one process: {time.time() - started:.1f} s")

    def info(path):
        text = subprocess.run([args.resmr, "info", "--regions", path], check=True, capture_output=True,
                              text=True).stdout
        return json.loads(text)

    a, b = info(parallel), info(single)
    regions = a["region_list"]
    if len(regions) < 20 or a["leaf_level"] < 3:
        print(f"FAIL: too small a hierarchy to test: {len(regions)} regions, leaf level {a['leaf_level']}")
        failed = True
    for key in ("dims", "leaf_level", "cmax", "regions", "levels", "hash", "geometry_id", "bytes"):
        if a[key] != b[key]:
            print(f"FAIL: {key} differs: two ranks {a[key]}, one process {b[key]}")
            failed = True
    if a["region_list"] != b["region_list"]:
        differ = [x for x, y in zip(a["region_list"], b["region_list"]) if x != y]
        print(f"FAIL: {len(differ)} region records differ, first: {differ[:2]}")
        failed = True
    # The parallel file is a real one: chunks of both ranks, readable end to end (the finest
    # level of a small model; a big one's would not fit in memory, and its chunks' CRCs are
    # compared above).
    if a["cells"] <= 10_000_000:
        level = simple.ExtractMultiresolutionLevel(FileName=parallel, Level=a["leaf_level"])
        level.UpdatePipeline()
        cells = level.GetDataInformation().GetNumberOfCells()
        if cells <= 0:
            print(f"FAIL: finest level of the two-rank file has {cells} cells")
            failed = True
    if not failed:
        print(f"MPI build equivalent: {len(regions)} regions, {a['leaf_level'] + 1} levels, "
              f"{a['hash']['cells']} hashed cells, geometry {a['geometry_id']}")
    if not failed and a["cells"] > 10_000_000:
        for path in (parallel, single):  # large: nothing to look at afterwards
            os.remove(path)
    return failed


# Rank 1 waits for rank 0's build and comparison on a file, sleeping: an MPI barrier polls,
# and its busy core would take one of the two the one-process build runs on.
finished = os.path.join(args.temp, "rank0-finished")
if rank == 0 and os.path.exists(finished):
    os.remove(finished)
controller.Barrier()
failed = False
if rank == 0:
    try:
        failed = build_one_process_and_compare()
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
