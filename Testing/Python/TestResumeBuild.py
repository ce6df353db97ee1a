"""A build killed with SIGKILL after some levels resumes from its last finished level and
writes the file an uninterrupted build writes (issue 6: "a killed build resumes from the last
finished level").

usage: TestResumeBuild.py RESMR TEMP
"""
import json
import os
import shutil
import signal
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
arguments = ["--cmax", "64", "--threads", "1", "--quiet"]
failures = []

# Kill it once a level above the leaves has finished (its manifest is in place).
process = subprocess.Popen([resmr, "build", model, "-o", killed] + arguments, stdout=subprocess.DEVNULL)
deadline = time.time() + 300
leaf = None
stopped_at = None
while time.time() < deadline and process.poll() is None:
    if os.path.isdir(scratch):
        levels = sorted(int(name.split("-")[1].split(".")[0]) for name in os.listdir(scratch)
                        if name.startswith("level-") and name.endswith(".rank-0"))
        if levels and leaf is None:
            leaf = levels[-1]
        if leaf is not None and len(levels) >= 3:
            process.send_signal(signal.SIGKILL)
            process.wait()
            stopped_at = levels[0]
            break
    time.sleep(0.02)
if stopped_at is None:
    failures.append(f"the build was not caught between levels (exit {process.poll()}); make the model bigger")
else:
    print(f"killed after level {stopped_at} finished (leaf level {leaf})")
    if os.path.exists(killed):
        failures.append("a killed build left a file under the final name")
    # Run again: it must resume, not start over.
    result = subprocess.run([resmr, "build", model, "-o", killed] + arguments, capture_output=True, text=True)
    if result.returncode != 0:
        failures.append(f"resumed build failed: {result.stderr}")
    else:
        report = json.loads(result.stdout)
        resumed = report["resumed_from_level"]
        print(f"resumed from level {resumed}")
        if resumed < 0 or resumed > stopped_at:
            failures.append(f"resumed from level {resumed}, expected {stopped_at} or a later-finished level")
        if os.path.exists(scratch):
            failures.append("the scratch folder is left after a successful build")

    # Same file as an uninterrupted build.
    subprocess.run([resmr, "build", model, "-o", whole] + arguments, check=True, stdout=subprocess.DEVNULL)

    def info(path):
        return json.loads(subprocess.run([resmr, "info", "--regions", path], check=True, capture_output=True,
                                         text=True).stdout)

    if not failures:
        a, b = info(killed), info(whole)
        for key in ("levels", "hash", "geometry_id", "region_list"):
            if a[key] != b[key]:
                failures.append(f"{key} differs between the resumed and the uninterrupted build")

    # --fresh ignores a scratch folder and starts over.
    process = subprocess.Popen([resmr, "build", model, "-o", killed] + arguments, stdout=subprocess.DEVNULL)
    while process.poll() is None and not (os.path.isdir(scratch) and any(
            n.startswith("level-") for n in os.listdir(scratch))):
        time.sleep(0.02)
    process.send_signal(signal.SIGKILL)
    process.wait()
    result = subprocess.run([resmr, "build", model, "-o", killed, "--fresh"] + arguments, capture_output=True,
                            text=True)
    if result.returncode != 0 or json.loads(result.stdout)["resumed_from_level"] != -1:
        failures.append("--fresh did not start over")

for failure in failures:
    print("FAIL: " + failure)
if failures:
    sys.exit(1)
print("resume test passed")
