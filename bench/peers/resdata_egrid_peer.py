#!/usr/bin/env python3
"""Peer: resdata (PyPI, Equinor's former libecl) grid, INIT and restart reading.

    bench/scratch/venv/bin/python bench/peers/resdata_egrid_peer.py GRID.EGRID [RUNS] [SWITCHES]

Open: resdata.grid.Grid on the EGRID (reads COORD, ZCORN, ACTNUM and builds its cells);
ResdataFile on the INIT, every numeric array with one value per cell or active cell (first
occurrence, headers left out: the arrays resmr lists) loaded and put into a per-cell numpy
array; ResdataFile on the unified restart (indexes it). Step switch: PRESSURE, SWAT, SGAS of
the step (iget_named_kw; ResdataFile on the per-step Xnnnn file when restarts are not
unified), put into per-cell float32 arrays allocated beforehand.
"""

import os
import sys
import warnings

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _egrid_peer as peer  # noqa: E402

import numpy as np  # noqa: E402
import resdata  # noqa: E402
from resdata.grid import Grid  # noqa: E402
from resdata.resfile import ResdataFile  # noqa: E402

warnings.simplefilter("ignore", DeprecationWarning)
NUMERIC = {"INTE", "REAL", "DOUB", "LOGI"}


def open_(path):
    grid = Grid(path)
    nx, ny, nz, nact = grid.get_dims()
    cells = nx * ny * nz
    actnum = grid.export_actnum()  # keep the keyword alive while its view is used
    mask = actnum.numpy_view() > 0
    state = {"grid": grid, "cells": cells, "mask": mask, "init": {}}
    init_path, unified, per_step = peer.companions(path)
    if init_path:
        init = ResdataFile(init_path)
        state["init_file"] = init
        for name, count, kind in init.headers:
            if kind in NUMERIC and count in (nact, cells) and name not in peer.HEADERS \
                    and name not in state["init"]:
                values = init.iget_named_kw(name, 0).numpy_view()
                state["init"][name] = peer.to_cells(values, mask, cells)
    if unified:
        rst = ResdataFile(unified)
        state.update(rst=rst, steps=list(rst.report_list))
    else:
        state.update(files=per_step, steps=[int(p[-4:]) for p in per_step])
    return state


def read_step(state, index, outputs):
    found = 0
    if "rst" in state:
        f, occurrence = state["rst"], index
    else:
        f, occurrence = ResdataFile(state["files"][index]), 0
    for name, out in outputs.items():
        if f.num_named_kw(name) > occurrence:
            peer.to_cells(f.iget_named_kw(name, occurrence).numpy_view(), state["mask"],
                          state["cells"], out)
            found += 1
    return found


def describe(state):
    return {"cells": state["cells"], "init_arrays": list(state["init"]),
            "steps": len(state["steps"])}


if __name__ == "__main__":
    peer.run("resdata (Grid, ResdataFile)", "resdata " + resdata.__version__, open_,
             read_step, lambda s: s["steps"], describe)
