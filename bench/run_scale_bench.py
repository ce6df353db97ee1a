"""The paper's scale on one workstation (paper Tables 1-2 and Fig. 14): one synthetic model
built, given properties of several report steps, and flown along the view benchmark's path.

  python3 bench/run_scale_bench.py --resmr build/bin/resmr --scratch DIR \
      [--model synth:4500x2800x100:1] [--steps 2] [--memory 8G] \
      [--pvpython pvpython --plugin PLUGIN.so --frames 1000 --budget 512]

Records in bench/results/scale-NAME.{json,md}: the build (time, peak RSS against --memory,
peak scratch and scratch + file a cell, the file a cell, levels), the property file (time,
peak RSS, bytes, the packed tables against a full 3D table of the model, which the paper
gives as 3.5%), and with --pvpython the view benchmark on the built file (first image, frame
times at --fps, resident memory against --budget), with the machine and free disk. The model
and its property file stay in DIR (the view benchmark's names), so a run can be resumed:
what exists is not built again (--rebuild builds anyway).
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time

import run_build_bench as build_bench

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

parser = argparse.ArgumentParser()
parser.add_argument("--resmr", required=True)
parser.add_argument("--scratch", required=True)
parser.add_argument("--model", default="synth:4500x2800x100:1")
parser.add_argument("--steps", type=int, default=2)
parser.add_argument("--memory", default="8G")
parser.add_argument("--pvpython")
parser.add_argument("--plugin")
parser.add_argument("--frames", type=int, default=1000)
parser.add_argument("--budget", type=int, default=512, help="view memory budget, MB")
parser.add_argument("--moving-floor", type=float, default=0.5,
                    help="the view's Moving Resolution Floor; another than 0.5 is recorded beside the default's")
parser.add_argument("--rebuild", action="store_true")
parser.add_argument("--report-only", action="store_true")
args = parser.parse_args()

match = re.fullmatch(r"synth:(\d+)x(\d+)x(\d+)(?::(\d+))?", args.model)
if not match:
    sys.exit("--model must be synth:NIxNJxNK[:SEED]")
nx, ny, nz = (int(v) for v in match.groups()[:3])
seed = int(match.group(4) or 1)
name = f"synth_{nx}x{ny}x{nz}"
os.makedirs(args.scratch, exist_ok=True)
resmr_path = os.path.join(args.scratch, name + ".resmr")
out_base = os.path.join(ROOT, "bench", "results", f"scale-{nx}x{ny}x{nz}")


def machine():
    host = build_bench.machine()
    host["free_disk_gb"] = round(shutil.disk_usage(args.scratch).free / 1e9, 1)
    return host


def timed(command):
    """Runs `command` under /usr/bin/time -v: (JSON report on stdout, wall s, peak RSS MB)."""
    start = time.time()
    run = subprocess.run(["/usr/bin/time", "-v"] + command, capture_output=True, text=True)
    wall = time.time() - start
    if run.returncode != 0:
        sys.exit(f"{' '.join(command)} failed:\n{run.stderr[-2000:]}")
    peak = re.search(r"Maximum resident set size \(kbytes\): (\d+)", run.stderr)
    return json.loads(run.stdout.strip().splitlines()[-1]), wall, int(peak.group(1)) / 1024


def build_and_properties(results):
    cells = nx * ny * nz
    if args.rebuild or not os.path.exists(resmr_path):
        report, wall, rss = timed([args.resmr, "build", args.model, "-o", resmr_path, "--memory", args.memory,
                                   "--quiet"])
        results["build"] = {"report": report, "wall_s": wall, "peak_rss_mb": rss, "memory": args.memory}
        save(results)
    info = json.loads(subprocess.run([args.resmr, "info", resmr_path], check=True, capture_output=True,
                                     text=True).stdout)
    results["info"] = info
    properties = resmr_path + "p"
    if args.rebuild or not os.path.exists(properties):
        source = f"synth:{nx}x{ny}x{nz}:{seed}:{args.steps}"
        report, wall, rss = timed([args.resmr, "add-properties", resmr_path, source, "-o", properties])
        results["properties"] = {"report": report, "wall_s": wall, "peak_rss_mb": rss, "source": source,
                                 "bytes": os.path.getsize(properties)}
        save(results)
    results["cells"] = cells
    save(results)


def view_key():
    return "view" if args.moving_floor == 0.5 else f"view_floor{args.moving_floor:g}"


def view(results):
    out = out_base + "-" + view_key().replace("_", "-")
    command = ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", args.pvpython,
               os.path.join(ROOT, "bench", "run_view_bench.py"), "--plugin", args.plugin, "--resmr", args.resmr,
               "--scratch", args.scratch, "--models", f"synth:{nx}x{ny}x{nz}", "--frames", str(args.frames),
               "--budget", str(args.budget), "--moving-floor", str(args.moving_floor), "--out", out]
    subprocess.run(command, check=True)
    with open(out + ".json") as handle:
        results[view_key()] = json.load(handle)
    results["view_budget_mb"] = args.budget
    save(results)


def save(results):
    # The scratch folder is the runner's; a reader of the results sees SCRATCH.
    text = json.dumps(results, indent=1).replace(os.path.abspath(args.scratch), "SCRATCH")
    with open(out_base + ".json", "w") as handle:
        handle.write(text)


def report(results):
    host = results["machine"]
    cells = results.get("cells", nx * ny * nz)
    lines = [f"# {cells:,} cells on one workstation ({args.model})", "",
             f"Machine: {host['cpu']}, {host['cores']} cores, {host['memory_gib']} GiB, "
             f"{host['free_disk_gb']} GB free disk at the start; {host['os']}.", ""]
    build = results.get("build")
    if build:
        r = build["report"]
        lines += ["## Build (`resmr build " + args.model + f" --memory {build['memory']}`)", "",
                  "| cells | active | levels | regions | total s | cells/s | peak RSS MB | file GB | file B/cell "
                  "| peak scratch GB | scratch B/cell | scratch + file at peak, B/cell |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|",
                  f"| {r['cells']:,} | {r['active_cells']:,} | {r['leaf_level'] + 1} | {r['regions']} | "
                  f"{r['total_s']:.0f} | {r['cells_per_s']:,.0f} | {build['peak_rss_mb']:.0f} | "
                  f"{r['file_bytes'] / 1e9:.2f} | {r['bytes_per_cell']:.2f} | {r['peak_scratch_bytes'] / 1e9:.1f} | "
                  f"{r['peak_scratch_bytes'] / r['cells']:.1f} | {r['peak_disk_bytes'] / r['cells']:.1f} |", "",
                  f"Phases: partition {r['partition_s']:.0f} s, leaves {r['leaves_s']:.0f} s and levels "
                  f"{r['simplify_s']:.0f} s (interleaved, shared out by task time), the rest (property side, "
                  f"writing) {r['total_s'] - r['partition_s'] - r['leaves_s'] - r['simplify_s']:.0f} s; "
                  f"{r['tasks']} tasks on {r['threads']} threads.", ""]
    props = results.get("properties")
    if props:
        r = props["report"]
        hashed = results["info"]["hash"]
        slots = hashed["slots"]
        lines += ["## Properties (`resmr add-properties FILE " + props["source"] + "`)", "",
                  f"{props['wall_s']:.0f} s, peak RSS {props['peak_rss_mb']:.0f} MB, "
                  f"{props['bytes'] / 1e9:.2f} GB for {r.get('tables', '?')} tables. "
                  f"The perfect hash packs the {hashed['cells']:,} cells that extracted faces touch into "
                  f"{slots:,.0f} slots a table: with its offset table, {100 * hashed['packed_over_full_grid']:.1f}% "
                  f"of a full 3D table of the model's {cells:,} cells (a float a cell); counted as the paper "
                  f"counts (6 bytes a voxel and an offset), "
                  f"{100 * (slots + hashed['offsets']) / cells:.1f}% (the paper's C1200: 3.5%).", ""]
    for key in sorted(k for k in results if k == "view" or k.startswith("view_floor")):
        shown = results[key]
        for e in shown if isinstance(shown, list) else shown.get("models", []):
            floor = e.get("moving_floor", 1.0)
            lines += [f"## View (bench/run_view_bench.py, 1280x720, llvmpipe, Moving Resolution Floor {floor:g})", "",
                      f"First image {e['first_image_s']:.2f} s; frame times p50 {e['p50_ms']:.0f} ms, "
                      f"p99 {e['p99_ms']:.0f} ms at {e.get('fps', 10)} FPS, "
                      f"{100 * e.get('frames_reduced', 0):.0f}% of the frames drawn at a reduced resolution; "
                      f"resident at most {e.get('max_resident_mb', 0):.0f} MB (budget "
                      f"{results.get('view_budget_mb', args.budget)} MB); process RSS at most "
                      f"{e.get('max_rss_mb', 0):.0f} MB.", ""]
    with open(out_base + ".md", "w") as handle:
        handle.write("\n".join(lines))
    print("\n".join(lines))


def main():
    results = {}
    if os.path.exists(out_base + ".json"):
        with open(out_base + ".json") as handle:
            results = json.load(handle)
    if not args.report_only:
        results.setdefault("machine", machine())
        results["model"] = args.model
        save(results)
        build_and_properties(results)
        if args.pvpython and args.plugin:
            view(results)
    report(results)


main()
