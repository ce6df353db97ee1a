#!/usr/bin/python3
"""Peer: OPM EclIO (Debian python3-opm-common), run with Debian's /usr/bin/python3.

    /usr/bin/python3 bench/peers/opm_eclio_peer.py GRID.EGRID [RUNS] [SWITCHES]

Open: opm.io.ecl.EclFile on the EGRID, COORD, ZCORN and ACTNUM loaded as numpy arrays;
EclFile on the INIT, every numeric array with one value per cell or active cell (first
occurrence, headers left out: the arrays resmr lists) loaded and put into a per-cell numpy
array; ERst on the unified restart (indexes the report steps). Step switch: PRESSURE, SWAT,
SGAS of the step via ERst (which loads the whole report step on first access), or via
EclFile on the per-step Xnnnn file, put into per-cell float32 arrays allocated beforehand.
"""

import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _egrid_peer as peer  # noqa: E402

from opm.io.ecl import EclFile, ERst, eclArrType  # noqa: E402

NUMERIC = {eclArrType.INTE, eclArrType.REAL, eclArrType.DOUB, eclArrType.LOGI}


def version():
    try:
        out = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "python3-opm-common"],
                             capture_output=True, text=True, check=True).stdout
        return "python3-opm-common " + out.strip()
    except (OSError, subprocess.CalledProcessError):
        return "opm-common (unknown version)"


def open_(path):
    grid = EclFile(path)
    head = grid["GRIDHEAD"]
    cells = int(head[1]) * int(head[2]) * int(head[3])
    state = {"coord": grid["COORD"], "zcorn": grid["ZCORN"], "cells": cells}
    names = [n for n, _, _ in grid.arrays]
    actnum = grid["ACTNUM"] if "ACTNUM" in names else None
    mask = actnum > 0 if actnum is not None else None
    nact = int(mask.sum()) if mask is not None else cells
    if mask is None:
        import numpy as np
        mask = np.ones(cells, dtype=bool)
    state.update(actnum=actnum, mask=mask, init={})
    init_path, unified, per_step = peer.companions(path)
    if init_path:
        init = EclFile(init_path)
        for name, kind, count in init.arrays:
            if kind in NUMERIC and count in (nact, cells) and name not in peer.HEADERS \
                    and name not in state["init"]:
                state["init"][name] = peer.to_cells(init[name], mask, cells)
    if unified:
        rst = ERst(unified)
        state.update(rst=rst, steps=list(rst.report_steps))
    else:
        state.update(files=per_step, steps=[int(p[-4:]) for p in per_step])
    return state


def read_step(state, index, outputs):
    found = 0
    if "rst" in state:
        rst, number = state["rst"], state["steps"][index]
        for name, out in outputs.items():
            if (name, number) in rst:
                peer.to_cells(rst[name, number], state["mask"], state["cells"], out)
                found += 1
    else:
        f = EclFile(state["files"][index])
        names = {n for n, _, _ in f.arrays}
        for name, out in outputs.items():
            if name in names:
                peer.to_cells(f[name], state["mask"], state["cells"], out)
                found += 1
    return found


def describe(state):
    return {"cells": state["cells"], "init_arrays": list(state["init"]),
            "steps": len(state["steps"])}


if __name__ == "__main__":
    peer.run("OPM EclIO (EclFile, ERst)", version(), open_, read_step,
             lambda s: s["steps"], describe)
