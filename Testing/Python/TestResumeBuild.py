"""A build killed with SIGKILL part-way resumes from the tasks its journal records (leaves and
diamonds) and writes the file an uninterrupted build writes; --fresh starts over.

usage: TestResumeBuild.py RESMR TEMP
"""
import json
import os
import shutil
import signal
import struct
import subprocess
import sys
import time

resmr, temp = sys.argv[1], sys.argv[2]
shutil.rmtree(temp, ignore_errors=True)
os.makedirs(temp)
model = "synth:160x120x24:3"
killed = os.path.join(temp, "killed.resmr")
whole = os.path.join(temp, "whole.resmr")
scratch = killed + ".scratch"
journal = os.path.join(scratch, "build.journal")
arguments = ["--cmax", "64", "--threads", "1", "--quiet"]
failures = []


def recorded_tasks():
    """Whole records in the build journal (magic, size, CRC-32, then the record)."""
    try:
        data = open(journal, "rb").read()
    except FileNotFoundError:
        return 0
    count, at = 0, 0
    while at + 12 <= len(data):
        magic, size, _ = struct.unpack_from("<III", data, at)
        if magic != 0x4C4E524A or at + 12 + size > len(data):
            break
        count, at = count + 1, at + 12 + size
    return count


def info(path):
    return json.loads(subprocess.run([resmr, "info", "--regions", path], check=True, capture_output=True,
                                     text=True).stdout)


# The uninterrupted build, and how many tasks it runs.
result = subprocess.run([resmr, "build", model, "-o", whole] + arguments, check=True, capture_output=True, text=True)
tasks = json.loads(result.stdout)["tasks"]
print(f"{tasks} tasks")

# Kill it once a third of its tasks are recorded.
process = subprocess.Popen([resmr, "build", model, "-o", killed] + arguments, stdout=subprocess.DEVNULL)
deadline = time.time() + 300
stopped_at = None
while time.time() < deadline and process.poll() is None:
    if recorded_tasks() >= tasks // 3:
        process.send_signal(signal.SIGKILL)
        process.wait()
        stopped_at = recorded_tasks()
        break
    time.sleep(0.005)
if stopped_at is None or stopped_at >= tasks:
    failures.append(f"the build was not caught part-way (exit {process.poll()}); make the model bigger")
else:
    print(f"killed with {stopped_at} of {tasks} tasks recorded")
    if os.path.exists(killed):
        failures.append("a killed build left a file under the final name")
    # Run again: it must resume, not start over.
    result = subprocess.run([resmr, "build", model, "-o", killed] + arguments, capture_output=True, text=True)
    if result.returncode != 0:
        failures.append(f"resumed build failed: {result.stderr}")
    else:
        report = json.loads(result.stdout)
        print(f"resumed with {report['resumed_tasks']} tasks done")
        if not report["resumed_partition"] or report["resumed_tasks"] < stopped_at:
            failures.append(f"resumed {report['resumed_tasks']} tasks and partition {report['resumed_partition']}, "
                            f"expected the partition and at least {stopped_at} tasks")
        if os.path.exists(scratch):
            failures.append("the scratch folder is left after a successful build")
    if not failures:
        a, b = info(killed), info(whole)
        for key in ("levels", "hash", "geometry_id", "region_list"):
            if a[key] != b[key]:
                failures.append(f"{key} differs between the resumed and the uninterrupted build")

    # --fresh ignores a scratch folder and starts over.
    process = subprocess.Popen([resmr, "build", model, "-o", killed] + arguments, stdout=subprocess.DEVNULL)
    while process.poll() is None and recorded_tasks() < 3:
        time.sleep(0.005)
    process.send_signal(signal.SIGKILL)
    process.wait()
    result = subprocess.run([resmr, "build", model, "-o", killed, "--fresh"] + arguments, capture_output=True,
                            text=True)
    if result.returncode != 0 or json.loads(result.stdout)["resumed_tasks"] != 0 or \
            json.loads(result.stdout)["resumed_partition"]:
        failures.append("--fresh did not start over")

for failure in failures:
    print("FAIL: " + failure)
if failures:
    sys.exit(1)
print("resume test passed")
