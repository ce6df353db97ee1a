"""Generated models against independent readers, recorded: for several sizes and seeds,
`resmr synth` writes an EGRID (+ INIT + UNRST) and the project's `resmr info`, OPM EclIO and
resdata (PyPI) must report the same dims, active cells and report steps; at 100M cells the
plugin's EGRIDReader must refuse the grid (too big for memory at full resolution) quickly,
pointing to the multiresolution path.

usage: python3 bench/check_synth_validity.py [--with-100m]
Needs: build/bin/resmr, /usr/bin/python3 with opm (python3-opm-common), a Python with
resdata (bench/scratch/venv, or --resdata-python), pvpython for the refusal check.
Writes bench/results/synth_validity.{md,json}.
"""
import argparse
import json
import os
import platform
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRATCH = os.path.join(ROOT, "bench", "scratch", "validity")
PLUGIN = os.path.join(ROOT, "build", "lib", "paraview-plugins", "ReservoirMultiresolution",
                      "ReservoirMultiresolution.so")

CASES = [  # nx, ny, nz, seed, steps
    (60, 50, 12, 1, 3),
    (60, 50, 12, 2, 0),
    (97, 61, 7, 12345, 2),
    (200, 150, 40, 3, 5),
    (500, 200, 100, 1, 2),
]

OPM = ("import sys, json; from opm.io.ecl import EGrid, ERst; g = EGrid(sys.argv[1]); "
       "r = sys.argv[2]; steps = len(ERst(r).report_steps) if r else 0; "
       "print(json.dumps([list(g.dimension), g.active_cells, steps]))")
RESDATA = ("import sys, json, warnings; warnings.simplefilter('ignore'); import resdata.grid as G, "
           "resdata.resfile as F; g = G.Grid(sys.argv[1]); r = sys.argv[2]; "
           "steps = len(F.ResdataRestartFile(g, r).headers()) if r else 0; "
           "print(json.dumps([[g.get_nx(), g.get_ny(), g.get_nz()], g.get_num_active(), steps]))")
REFUSAL = """
import sys, time
from paraview import simple
simple.LoadPlugin(sys.argv[1], remote=False, ns=vars(simple))
start = time.time()
reader = simple.EGRIDReader(FileName=sys.argv[2])
reader.UpdatePipeline()
reader.UpdatePropertyInformation()
print("SECONDS", time.time() - start)
print("ERROR", reader.GetPropertyValue("LastError"))
"""


def run(command):
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{command}: {done.stderr[-2000:]}")
    return done.stdout


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--resmr", default=os.path.join(ROOT, "build", "bin", "resmr"))
    parser.add_argument("--resdata-python", default=os.path.join(ROOT, "bench", "scratch", "venv", "bin", "python"))
    parser.add_argument("--with-100m", action="store_true")
    args = parser.parse_args()
    os.makedirs(SCRATCH, exist_ok=True)
    cases = CASES + ([(1000, 1000, 100, 1, 0)] if args.with_100m else [])
    rows = []
    for nx, ny, nz, seed, steps in cases:
        path = os.path.join(SCRATCH, f"V{nx}x{ny}x{nz}s{seed}.EGRID")
        summary = json.loads(run([args.resmr, "synth", str(nx), str(ny), str(nz), "--seed", str(seed),
                                  "--steps", str(steps), "--quiet", "-o", path]))
        restart = path[:-5] + "UNRST" if steps else ""
        info = json.loads(run([args.resmr, "info", path]))
        ours = [info["dims"], info["active"], len(info["steps"])]
        opm = json.loads(run(["/usr/bin/python3", "-c", OPM, path, restart]))
        big = nx * ny * nz > 20_000_000
        resdata = None if big else json.loads(run([args.resdata_python, "-c", RESDATA, path, restart]))
        expected = [[nx, ny, nz], summary["active"], steps]
        row = {"dims": [nx, ny, nz], "seed": seed, "steps": steps, "generator": expected, "resmr_info": ours,
               "opm": opm, "resdata": resdata,
               "agree": ours == expected and opm == expected and (resdata is None or resdata == expected),
               "fractions": {k: summary[k] for k in ("outside_fraction", "pinched_fraction", "water_fraction",
                                                    "fault_face_fraction")}}
        if big:
            script = os.path.join(SCRATCH, "refusal.py")
            with open(script, "w") as handle:
                handle.write(REFUSAL)
            refusal = subprocess.run(["pvpython", "--force-offscreen-rendering", script, PLUGIN, path],
                                     capture_output=True, text=True).stdout
            seconds = float(refusal.split("SECONDS", 1)[1].split()[0])
            message = refusal.split("ERROR", 1)[1].strip()
            row["egridreader_refusal"] = {"seconds": seconds, "message": message,
                                          "refused": "multiresolution" in message}
            row["agree"] = row["agree"] and row["egridreader_refusal"]["refused"]
        rows.append(row)
        print(json.dumps(row), flush=True)
        for extension in ("EGRID", "INIT", "UNRST"):
            name = path[:-5] + extension
            if os.path.exists(name):
                os.remove(name)
    commit = run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"]).strip()
    cpu = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name")), "?")
    record = {"commit": commit, "machine": {"cpu": cpu, "cores": os.cpu_count(), "platform": platform.platform()},
              "cases": rows}
    results = os.path.join(ROOT, "bench", "results")
    with open(os.path.join(results, "synth_validity.json"), "w") as handle:
        json.dump(record, handle, indent=1)
    lines = [
        "# Generated models in independent readers",
        "",
        f"`bench/check_synth_validity.py`, commit {commit}, {cpu}, {os.cpu_count()} cores.",
        "Each model is written by `resmr synth`; `resmr info` (this project's EGRID reader), OPM EclIO",
        "(`python3-opm-common`) and resdata (PyPI) must report the generator's dims, active cells and",
        "report steps. resdata is skipped above 20M cells (it holds the whole grid in memory).",
        "",
        "| dims | seed | steps | active | resmr info | OPM | resdata | outside / pinched / water / fault faces |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        g = row["generator"]
        mark = lambda other: "-" if other is None else ("same" if other == g else f"**{other}**")
        f = row["fractions"]
        lines.append(f"| {'x'.join(map(str, row['dims']))} | {row['seed']} | {row['steps']} | {g[1]} | "
                     f"{mark(row['resmr_info'])} | {mark(row['opm'])} | {mark(row['resdata'])} | "
                     f"{f['outside_fraction']:.3f} / {f['pinched_fraction']:.3f} / {f['water_fraction']:.3f} / "
                     f"{f['fault_face_fraction']:.3f} |")
    for row in rows:
        if "egridreader_refusal" in row:
            r = row["egridreader_refusal"]
            lines += ["", f"EGRIDReader on the {'x'.join(map(str, row['dims']))} model: refused in "
                          f"{r['seconds']:.2f} s with: \"{r['message']}\""]
    lines += ["", "All agree." if all(r["agree"] for r in rows) else "**Some disagree: see above.**", ""]
    with open(os.path.join(results, "synth_validity.md"), "w") as handle:
        handle.write("\n".join(lines))
    return 0 if all(r["agree"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
