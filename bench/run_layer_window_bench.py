"""A leaf region read for a window of layers against whole, by mesh layout:

  python3 bench/run_layer_window_bench.py --tool build/bin/bench_layer_window \
      --models A.resmr B.resmr ... [--peers A_v9.resmr B_v9.resmr ...] [--out bench/results/layer_window]

For each model (this version's file: positions in layer groups) and its peer (the same model
built by a version before 10: positions in the mesh chunk), bench_layer_window reads every leaf
region for a window of 2 layers in the middle (a K slab) and for one at the top, and whole,
cold (pages dropped) and warm, in one run. Results and the machine go to OUT.json and OUT.md."""
import argparse
import json
import os
import subprocess

import bench_machine

parser = argparse.ArgumentParser()
parser.add_argument("--tool", required=True)
parser.add_argument("--models", nargs="+", required=True)
parser.add_argument("--peers", nargs="*", default=[])
parser.add_argument("--out", default="bench/results/layer_window")
args = parser.parse_args()


def layers(path):
    with open(path, "rb") as f:
        head = f.read(40)
    return int.from_bytes(head[32:40], "little")


rows = []
for n, model in enumerate(args.models):
    files = [model] + ([args.peers[n]] if n < len(args.peers) else [])
    nk = layers(model)
    for tag, first in (("middle", nk // 2 - 1), ("top", 0)):
        out = subprocess.run([args.tool, str(first), str(first + 1)] + files,
                             check=True, capture_output=True, text=True).stdout
        for line in out.splitlines():
            row = dict(json.loads(line), model=os.path.basename(model), window=tag, nk=nk)
            row["file"] = os.path.basename(row["file"])
            rows.append(row)
            print(json.dumps(row), flush=True)
bench_machine.write_results(
    args.out, rows, "A leaf region read for a window of layers, by mesh layout",
    "Every leaf region read with MultiresolutionFile::ReadRegionLayers for 2 layers and with ReadRegion whole, "
    "one pass cold (pages dropped), one warm; format 10 keeps positions in layer groups of 8 interfaces, format "
    "9 in the mesh chunk.",
    ["model", "file", "format", "leaves", "mesh bytes a leaf", "layers (from 1)", "window cold ms",
     "window warm ms", "whole cold ms", "whole warm ms"],
    lambda r: [r["model"], r["file"], r["version"], r["leaves"], f"{r['mesh_bytes_per_leaf']:,.0f}",
               f"{r['layers'][0]}-{r['layers'][1]} of {r['nk']}", r["window_cold_ms"], r["window_warm_ms"],
               r["whole_cold_ms"], r["whole_warm_ms"]])
