"""Benchmarks that set builds side by side keep one run a label in a JSON list."""
import json
import os


def store_run(json_path, run):
    """Adds `run` to the list in `json_path`, replacing a run of the same label; returns the list."""
    runs = json.load(open(json_path)) if os.path.exists(json_path) else []
    runs = [r for r in runs if r["label"] != run["label"]] + [run]
    with open(json_path, "w") as out:
        json.dump(runs, out, indent=1)
    return runs
