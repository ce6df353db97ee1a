"""A filtered leaf region's property values, tiles against bands of whole rows:

  python3 bench/run_leaf_values_bench.py --tool build/bin/bench_leaf_values --scratch DIR \
      --models A.resmr B.resmr ... [--table SWAT --step 1] [--out bench/results/leaf_values]

For each model (its .resmrp beside it), bench_leaf_values writes the table twice into DIR, in
this version's 64 x 64-column tiles and in bands of whole rows of at most 1 MB (version 4's
layout, the peer), and reads every leaf region's box of cells (all layers) from each, cold
(pages dropped) and warm. Results and the machine go to OUT.json and OUT.md."""
import argparse
import json
import os
import subprocess

import bench_machine

parser = argparse.ArgumentParser()
parser.add_argument("--tool", required=True)
parser.add_argument("--scratch", required=True)
parser.add_argument("--models", nargs="+", required=True)
parser.add_argument("--table", default="SWAT")
parser.add_argument("--step", default="1")
parser.add_argument("--out", default="bench/results/leaf_values")
args = parser.parse_args()


rows = []
for model in args.models:
    out = subprocess.run([args.tool, model, model + "p", args.table, args.step, args.scratch],
                         check=True, capture_output=True, text=True).stdout
    for line in out.splitlines():
        row = dict(json.loads(line), model=os.path.basename(model), table=f"{args.table} step {args.step}")
        rows.append(row)
        print(json.dumps(row), flush=True)
bench_machine.write_results(
    args.out, rows, "A filtered leaf region's property values: tiles against bands of whole rows",
    "Every leaf region's box of cells over all layers read with PropertyFile::ReadBox, one pass cold (pages "
    "dropped), one warm.",
    ["model", "table", "layout", "band", "leaves", "cells read", "layer bytes", "cold ms a leaf", "warm ms a leaf",
     "same values"],
    lambda r: [r["model"], r["table"], r["layout"], f"{r['band_rows']} x {r['band_columns']}", r["leaves"],
               f"{r['cells']:,}", f"{r['layer_bytes']:,}", r["cold_ms_per_leaf"], r["warm_ms_per_leaf"],
               r["same_values"]])
