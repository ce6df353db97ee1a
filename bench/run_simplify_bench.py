"""Column-collapse simplification benchmark (issue 5, paper Sec. 4.1): for each model, the
simplification to 50%, 10% and 1% of its columns, and the comparison with uniform B x B
coarsening (B = 2, 3) at the same column count, for the paper's selection (8 random
candidates) and the greedy queue. Records counts, inverted cells, scaled Jacobians, boundary
Hausdorff distance, input cells per second and peak memory in bench/results/simplify.{md,json}
and a plot of boundary error against cell count (simplify.png).

usage: python3 bench/run_simplify_bench.py [--big | --big-only] [--seeds N]
  --big-only: only the 10M-cell synthetic model (8 candidates, 50%, 10%, 1% and the 2x2
  comparison: each run there takes minutes, mostly the Hausdorff measure), into
  simplify_big.{md,json}
"""
import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.environ.get("RESMR_DATA_DIR", os.path.join(os.path.dirname(ROOT), "shared", "data"))
MODELS = [
    ("Reek", os.path.join(DATA, "reek/res2df_sim/eclipse/model/2_R001_REEK-0.EGRID")),
    ("Brugge", os.path.join(DATA, "brugge/Real0/BRUGGE_0000.EGRID")),
    ("Emerald", os.path.join(DATA, "emerald/eme_small_w_hole_grid_params.grdecl")),
    ("synthetic 1M", "synth:100x100x100:1"),
]
BIG = [("synthetic 10M", "synth:500x200x100:1")]
MODES = [("8 candidates", ["--candidates", "8"]), ("greedy", ["--greedy"])]


def simplify(resmr, model, *options):
    started = time.time()
    run = subprocess.run([resmr, "simplify", model, *options], capture_output=True, text=True)
    if run.returncode != 0:
        return {"error": run.stderr.strip()[-500:], "wall": time.time() - started}
    result = json.loads(run.stdout)
    result["wall"] = time.time() - started
    return result


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--resmr", default=os.path.join(ROOT, "build", "bin", "resmr"))
    parser.add_argument("--big", action="store_true", help="also the 10M-cell synthetic model")
    parser.add_argument("--big-only", action="store_true", help="only the 10M-cell model, fewer runs")
    parser.add_argument("--seeds", type=int, default=1)
    parser.add_argument("--report-only", action="store_true", help="rewrite the table and plot from the saved JSON")
    args = parser.parse_args()
    models = BIG if args.big_only else MODELS + (BIG if args.big else [])
    modes = MODES[:1] if args.big_only else MODES
    fractions = (0.5, 0.1, 0.01)
    blocks = (2,) if args.big_only else (2, 3)
    stem = "simplify_big" if args.big_only else "simplify"
    rows = []
    results = os.path.join(ROOT, "bench", "results")
    saved = None
    if args.report_only:
        with open(os.path.join(results, stem + ".json")) as handle:
            saved = json.load(handle)
        rows = saved["rows"]
        models = [(name, None) for name, _ in models if any(r["model"] == name for r in rows)]
    for name, model in ([] if args.report_only else models):
        for mode, options in modes:
            for seed in range(1, args.seeds + 1):
                for fraction in fractions:
                    r = simplify(args.resmr, model, "--fraction", str(fraction), "--seed", str(seed), *options)
                    rows.append({"model": name, "mode": mode, "seed": seed, "kind": "fraction", "fraction": fraction, **r})
                    print(json.dumps({k: rows[-1].get(k) for k in ("model", "mode", "fraction", "columns_after",
                                                                   "target_columns", "wall")}), flush=True)
                for block in blocks:
                    r = simplify(args.resmr, model, "--uniform", str(block), "--seed", str(seed), *options)
                    rows.append({"model": name, "mode": mode, "seed": seed, "kind": "uniform", "block": block, **r})
                    print(json.dumps({k: rows[-1].get(k) for k in ("model", "mode", "block", "columns_after",
                                                                   "target_columns", "wall")}), flush=True)
    if saved:
        commit, cpu, cores = saved["commit"], saved["cpu"], saved["cores"]
    else:
        commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
        cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
        cores = os.cpu_count()
        with open(os.path.join(results, stem + ".json"), "w") as handle:
            json.dump({"commit": commit, "cpu": cpu, "cores": cores, "rows": rows}, handle, indent=1)

    def quality(r):
        q, before = r.get("quality_after", {}), r.get("quality_before", {})
        repaired = ""
        if r.get("straightened_columns") or r.get("inverted_columns_collapsed"):
            repaired = (f" (repaired: {r.get('straightened_columns', 0)} straightened, up to "
                        f"{r.get('straightened_max_move', 0):.1f} m; {r.get('inverted_columns_collapsed', 0)} collapsed)")
        return f"{before.get('inverted', '?')} -> {q.get('inverted', '?')}{repaired} / {q.get('min_scaled_jacobian', 0):.3f}"

    def reached(r):
        if r["reached_target"]:
            return "yes"
        # Every connected part keeps at least one column: that many is as far as it goes.
        if r["columns_after"] == r.get("connected_parts_after", -1):
            return f"no: 1 column a part ({r['columns_after']} parts)"
        return "**no**"

    lines = ["# Column-collapse simplification (issue 5, paper Sec. 4.1)", "",
             f"`bench/run_simplify_bench.py` at commit {commit}, {cpu}, {cores} cores, one thread.",
             "Boundary error: two-sided Hausdorff distance between the external boundaries (top, bottom,",
             "faults, active limits) of the simplified and the original mesh, metres. Input cells/s counts",
             "the completed columns' cells over build + simplification time. Inverted cells: scaled",
             "Jacobian below zero; Brugge and Emerald have such cells as delivered (ParaView's Mesh Quality",
             "counts 97 and 285 in the whole grids). They are repaired first: a column on the outline whose",
             "outer corner (a node of that column only) turns inward has that corner moved out past the chord",
             "of its neighbours (\"straightened\", the largest move shown); columns still inverted are",
             "collapsed before any other. A collapse never creates an inverted cell. Rotations / relaxations / chords: edge rotations, whole-mesh smoothing",
             "passes and chord collapses made when collapses ran out. Parts (before / after): pieces joined by no shared edge",
             "(fault blocks cut off all round, isolated columns); no collapse joins two, so a target below",
             "that count cannot be reached by any column-collapse method.", "",
             "Selection: \"8 candidates\" is the paper's (Wu-Kobbelt multiple choice), what `resmr simplify`",
             "and the `SimplifyReservoirGrid` filter use by default, and what the issue's 100,000 input cells/s",
             "target is for. \"greedy\" (`--greedy`, ours) always takes the cheapest collapse of the whole",
             "mesh from a priority queue: slower, shown for its error.", "",
             "## Simplification to a fraction of the columns", "",
             "| model | selection | seed | target | columns before -> after | parts | reached | rotations / relaxations / chords | inverted before -> after / min scaled Jacobian | boundary error m | input cells/s | peak RSS MB |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["kind"] != "fraction":
            continue
        if "error" in r:
            lines.append(f"| {r['model']} | {r['mode']} | {r['seed']} | {r['fraction']:.0%} | error: {r['error'][:80]} | | | | | | | |")
            continue
        lines.append(f"| {r['model']} | {r['mode']} | {r['seed']} | {r['fraction']:.0%} | {r['columns_before']} -> "
                     f"{r['columns_after']} | {r.get('connected_parts', '?')} / {r.get('connected_parts_after', '?')} | {reached(r)} | "
                     f"{r.get('rotations', '?')} / {r.get('relaxations', '?')} / {r['operators'].get('chord', '?')} | {quality(r)} | "
                     f"{r['boundary_distance']['hausdorff']:.1f} | {r['input_cells_per_second']:,.0f} | {r['peak_rss_mb']:.0f} |")
    lines += ["", "## Against uniform B x B coarsening at the same column count", "",
              "| model | selection | seed | B | columns | ours: boundary error m | uniform: boundary error m | lower than uniform | ours inverted | uniform inverted |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    beaten = []
    for r in rows:
        if r["kind"] != "uniform" or "error" in r:
            continue
        ours, theirs = r["boundary_distance"]["hausdorff"], r["uniform"]["boundary_distance"]["hausdorff"]
        better = ours < theirs and r["reached_target"]
        beaten.append(better)
        lines.append(f"| {r['model']} | {r['mode']} | {r['seed']} | {r['block']} | {r['columns_after']} (target "
                     f"{r['target_columns']}) | {ours:.1f} | {theirs:.1f} | {'yes' if better else '**no**'} | "
                     f"{r['quality_after']['inverted']} | {r['uniform']['quality']['inverted']} |")
    lines += ["", f"Lower than uniform in {sum(beaten)} of {len(beaten)} comparisons.", ""]
    with open(os.path.join(results, stem + ".md"), "w") as handle:
        handle.write("\n".join(lines))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        figure, axes = plt.subplots(1, len(models), figsize=(4 * len(models), 3.5), squeeze=False)
        axes = axes[0]
        for axis, (name, _) in zip(axes, models):
            for mode, _ in modes:
                points = sorted((r["cells_after"], r["boundary_distance"]["hausdorff"]) for r in rows
                                if r["model"] == name and r["mode"] == mode and "error" not in r)
                axis.plot([p[0] for p in points], [p[1] for p in points], "o-", label=mode)
            uniform = sorted((r["uniform"]["columns"] * r["layers"], r["uniform"]["boundary_distance"]["hausdorff"])
                             for r in rows if r["model"] == name and r["kind"] == "uniform" and "error" not in r)
            axis.plot([p[0] for p in uniform], [p[1] for p in uniform], "s--", label="uniform")
            axis.set_title(name)
            axis.set_xlabel("cells")
            axis.set_ylabel("boundary error (m)")
        axes[0].legend()
        figure.tight_layout()
        figure.savefig(os.path.join(results, stem + ".png"), dpi=90)
    except ImportError:
        print("matplotlib missing: no plot", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
