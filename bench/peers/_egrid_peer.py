"""Shared driver of the EGRID-load peers: times `open` (EGRID + INIT, restart index) and
step switches the way bench_egrid_load does, and prints one JSON line per measurement.

    PEER GRID.EGRID RUNS SWITCHES

A peer supplies open(path) -> state (holding per-cell arrays as numpy) and
read_step(state, step_index, outputs) filling the per-cell float32 arrays in `outputs`
(PRESSURE, SWAT, SGAS, those present). Loads are run RUNS times, each freed before the next;
the last one is kept for SWITCHES step switches cycling through the steps, the first step
read once untimed, outputs allocated once beforehand (as bench_egrid_load does).
"""

import gc
import json
import resource
import sys
import time

import numpy as np

DYNAMIC = ("PRESSURE", "SWAT", "SGAS")


def peak_rss_bytes():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # Linux: KiB


def minor_faults():
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt


def to_cells(values, mask, cells, out=None):
    """Per-cell array from one value per cell or per active cell (inactive cells 0)."""
    if out is None:
        out = np.empty(cells, dtype=np.int32 if values.dtype.kind in "iub" else np.float32)
    if len(values) == cells:
        out[:] = values
    else:
        out[~mask] = 0
        out[mask] = values
    return out


def emit(record):
    print(json.dumps(record), flush=True)


def run(tool, version, open_fn, read_step, steps_of, describe=None):
    path = sys.argv[1]
    runs = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    switches = int(sys.argv[3]) if len(sys.argv) > 3 else runs
    rss_before = peak_rss_bytes()
    state = None
    for r in range(1, runs + 1):
        state = None
        gc.collect()
        faults = minor_faults()
        start = time.perf_counter()
        state = open_fn(path)
        seconds = time.perf_counter() - start
        record = {"kind": "load", "tool": tool, "version": version, "run": r,
                  "seconds": round(seconds, 6), "minor_faults": minor_faults() - faults,
                  "peak_rss_bytes": peak_rss_bytes(), "rss_before_open_bytes": rss_before}
        if describe:
            record.update(describe(state))
        emit(record)
    steps = steps_of(state)
    if len(steps) < 2 or switches <= 0:
        return
    cells = state["cells"]
    outputs = {name: np.zeros(cells, dtype=np.float32) for name in DYNAMIC}
    read_step(state, 0, outputs)
    current = 0
    for s in range(1, switches + 1):
        nxt = (current + 1) % len(steps)
        faults = minor_faults()
        start = time.perf_counter()
        found = read_step(state, nxt, outputs)
        seconds = time.perf_counter() - start
        emit({"kind": "switch", "tool": tool, "switch": s, "from": steps[current],
              "to": steps[nxt], "arrays": found, "seconds": round(seconds, 6),
              "minor_faults": minor_faults() - faults, "peak_rss_bytes": peak_rss_bytes()})
        current = nxt


def companions(path):
    """(INIT path or None, unified restart path or None, sorted per-step restart paths):
    STEM.INIT, STEM.UNRST, STEM.Xnnnn beside STEM.EGRID, either case."""
    import glob
    import os
    import re
    stem = path[:-len(".EGRID")] if path.upper().endswith(".EGRID") else path

    def first(*exts):
        for ext in exts:
            if os.path.exists(stem + ext):
                return stem + ext
        return None

    init = first(".INIT", ".init")
    unified = first(".UNRST", ".unrst")
    per_step = sorted(p for p in glob.glob(glob.escape(stem) + ".*")
                      if re.fullmatch(r"\.[Xx]\d{4}", p[len(stem):]))
    return init, unified, per_step


HEADERS = {"INTEHEAD", "LOGIHEAD", "DOUBHEAD", "SEQNUM", "ENDSOL", "STARTSOL", "TABDIMS",
           "TAB", "ENDLGR", "LGRHEADI", "LGRHEADQ", "LGRHEADD", "IGRP", "SGRP", "XGRP",
           "ZGRP", "IWEL", "SWEL", "XWEL", "ZWEL", "ICON", "SCON", "XCON"}
