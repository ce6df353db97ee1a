"""Disk of a hierarchy build: the peak scratch the build reports stays within the bound its
free-disk check assumes (BuildDiskNeed) on a 10M-cell model; a build the disk cannot hold is
refused before any work, saying what it needs; and a build stopped by a full disk in any phase
(the partition pass, resumed part-way from its last checkpoint; the leaves and diamonds,
resumed from the tasks its journal records; the writing of the file) keeps what it finished,
resumes when there is room, and writes the file an uninterrupted build writes.

The full disks are small tmpfs filesystems mounted in a private mount namespace (unshare -m),
grown after the failure (mount -o remount,size=...) for the resumed run, to more than the
free-disk check asks of a build that starts over.

usage: TestBuildDiskFull.py RESMR TEMP
"""
import json
import os
import shutil
import subprocess
import sys

resmr, temp = sys.argv[1], sys.argv[2]
shutil.rmtree(temp, ignore_errors=True)
os.makedirs(temp)
failures = []
# BuildDiskNeed in HierarchyBuilder.h (one process): bytes a cell, a column and fixed bytes of
# the scratch, and of the file.
SCRATCH_BYTES_PER_CELL, SCRATCH_BYTES_PER_COLUMN, SCRATCH_FIXED = 24, 64, 256 << 20
FILE_BYTES_PER_CELL, FILE_FIXED = 16, 64 << 20


def build(model, output, *extra):
    result = subprocess.run([resmr, "build", model, "-o", output, "--quiet"] + list(extra), capture_output=True,
                            text=True)
    return result.returncode, (json.loads(result.stdout) if result.returncode == 0 else None), result.stderr


def info(path):
    return json.loads(subprocess.run([resmr, "info", "--regions", path], check=True, capture_output=True,
                                     text=True).stdout)


# 1. The peak scratch of a 10M-cell build, measured while it runs, within the stated bound.
big = os.path.join(temp, "big.resmr")
code, report, error = build("synth:1000x1000x10:1", big)
if code != 0:
    failures.append(f"10M build failed: {error}")
else:
    cells = report["cells"]
    per_cell = report["peak_scratch_bytes"] / cells
    print(f"10M: peak scratch {report['peak_scratch_bytes'] / 1e6:.0f} MB ({per_cell:.1f} B a cell), "
          f"with the file {report['peak_disk_bytes'] / 1e6:.0f} MB, file {report['file_bytes'] / cells:.1f} B a cell")
    columns = 1000 * 1000
    if not 0 < report["peak_scratch_bytes"] <= SCRATCH_BYTES_PER_CELL * cells + SCRATCH_BYTES_PER_COLUMN * columns + \
            SCRATCH_FIXED:
        failures.append(f"peak scratch {per_cell:.1f} B a cell is over the bound the disk check assumes")
    if report["peak_disk_bytes"] < report["peak_scratch_bytes"]:
        failures.append("the peak with the file is below the peak of the scratch alone")
    if report["file_bytes"] > FILE_BYTES_PER_CELL * cells + FILE_FIXED:
        failures.append(f"file of {report['file_bytes'] / cells:.1f} B a cell, over {FILE_BYTES_PER_CELL}")
    os.remove(big)

# 2. Refused before any work when the disk cannot hold it (1.26 billion cells need about 50 GB
# of scratch and file; the scratch folder is put on a 64 MB filesystem).
unshare = shutil.which("unshare")
probe = subprocess.run([unshare, "-m", "true"], capture_output=True) if unshare else None
if probe is None or probe.returncode != 0:
    print("skipped: no private mount namespace here (unshare -m), which the full-disk cases need (root or "
          "user namespaces)")
    sys.exit(125 if not failures else 1)

disk = os.path.join(temp, "disk")
os.makedirs(disk)


def in_namespace(size, script):
    """Runs `script` (bash) with a tmpfs of `size` bytes mounted on `disk`, in a mount namespace of its own."""
    mount = f"mount -t tmpfs -o size={size} tmpfs '{disk}' && trap \"umount '{disk}'\" EXIT && "
    return subprocess.run([unshare, "-m", "--propagation", "private", "bash", "-c", mount + script],
                          capture_output=True, text=True)


run = in_namespace(64 << 20, f"'{resmr}' build synth:4500x2800x100 -o '{disk}/c1260.resmr' --quiet; echo rc=$?; "
                             f"ls -A '{disk}'")
lines = run.stdout.strip().splitlines()
print("1.26B on 64 MB:", run.stderr.strip().splitlines()[-1] if run.stderr.strip() else "(no message)")
if not lines or lines[0] != "rc=1":
    failures.append(f"a build the disk cannot hold was not refused: {run.stdout} {run.stderr}")
elif "not enough free disk" not in run.stderr or "GB of scratch" not in run.stderr or "--scratch" not in run.stderr:
    failures.append(f"the refusal does not say what the build needs and where to put it: {run.stderr}")
if len(lines) > 1:
    failures.append(f"the refused build left files: {lines[1:]}")

# 3. A full disk in each phase: the small model built with ever more room until it fits.
model, arguments = "synth:160x120x24:3", ["--cmax", "64", "--threads", "1"]
whole = os.path.join(temp, "whole.resmr")
code, report, error = build(model, whole, *arguments)
if code != 0:
    failures.append(f"uninterrupted build failed: {error}")
    report = {"peak_disk_bytes": 100 << 20}
expected = info(whole) if code == 0 else None
peak = report["peak_disk_bytes"]
phases = set()
partition_partway = False
flags = " ".join(arguments)


def kept_tasks(kept):
    return "build.journal" in kept


# The partition pass's compressed tiles take a few bytes a cell, far below a 20th of the peak:
# the smallest disks stop the build there.
sizes = [256 << 10, 512 << 10, 1 << 20, 3 << 19] + [max(1 << 20, (peak * step // 20) & ~4095) for step in range(1, 20)]
stops = {"partition": 0, "hierarchy": 0, "writing": 0}
for index, size in enumerate(sorted(set(sizes))):
    if stops["writing"] >= 2:
        break  # the larger disks stop the writing again, or fit
    if stops["hierarchy"] >= 4 and index % 2:
        continue  # the hierarchy spans most sizes: every other one resumes from enough points
    out = f"{disk}/m.resmr"
    script = (f"'{resmr}' build {model} -o '{out}' {flags} --quiet --no-disk-check > '{temp}/first.json' "
              f"2> '{temp}/first.err'; echo $? > '{temp}/first.rc'; "
              f"ls -A '{out}.scratch' > '{temp}/kept.txt' 2>/dev/null; "
              f"mount -o remount,size={peak * 2 + (1 << 30)} '{disk}' && "
              f"'{resmr}' build {model} -o '{out}' {flags} --quiet > '{temp}/second.json' 2> '{temp}/second.err' && "
              f"'{resmr}' info --regions '{out}' > '{temp}/info.json'")
    run = in_namespace(size, script)
    first_rc = int(open(f"{temp}/first.rc").read())
    if first_rc == 0:
        break  # it fits: every smaller disk was tried
    first_error = open(f"{temp}/first.err").read().strip()
    kept = open(f"{temp}/kept.txt").read().split() if os.path.exists(f"{temp}/kept.txt") else []
    if run.returncode != 0:
        failures.append(f"{size} B: the build did not resume on a bigger disk: {run.stderr} "
                        f"{open(temp + '/second.err').read()}")
        continue
    second = json.load(open(f"{temp}/second.json"))
    phase = ("partition" if not second["resumed_partition"] else
             "writing" if second["resumed_tasks"] == second["tasks"] else "hierarchy")
    phases.add(phase)
    stops[phase] += 1
    partway = phase == "partition" and second["resumed_layers"] > 0
    partition_partway = partition_partway or partway
    print(f"{size / 1e6:.1f} MB: stopped in the {phase} phase ({len(kept)} scratch files kept, "
          f"{second['resumed_layers']} layers and {second['resumed_tasks']} of {second['tasks']} tasks resumed): "
          f"{first_error.splitlines()[-1][:160]}")
    if "No space left" not in first_error and "disk full" not in first_error:
        failures.append(f"{size} B: the error does not say the disk is full: {first_error}")
    if (phase != "partition" or partway) and "kept" not in first_error:
        failures.append(f"{size} B: the error does not say the finished work is kept: {first_error}")
    if phase == "hierarchy" and second["resumed_tasks"] == 0 and kept_tasks(kept):
        failures.append(f"{size} B: tasks were recorded but none resumed")
    if expected is not None:
        resumed = json.load(open(f"{temp}/info.json"))
        for key in ("levels", "hash", "geometry_id", "region_list"):
            if resumed[key] != expected[key]:
                failures.append(f"{size} B ({phase}): {key} differs from the uninterrupted build")
for phase in ("partition", "hierarchy", "writing"):
    if phase not in phases:
        failures.append(f"no disk size stopped the build in its {phase} phase (sizes tried up to the peak)")
if not partition_partway:
    failures.append("no build stopped in its partition pass resumed part-way through it")

for failure in failures:
    print("FAIL: " + failure)
if failures:
    sys.exit(1)
print("disk test passed")
