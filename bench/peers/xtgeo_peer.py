#!/usr/bin/env python3
"""Peer: xtgeo (PyPI) grid import from GRDECL.

    bench/scratch/venv/bin/python bench/peers/xtgeo_peer.py DECK

xtgeo.grid_from_file(..., fformat="grdecl") reads the geometry keywords (SPECGRID, COORD,
ZCORN, ACTNUM, MAPAXES ...) and builds an xtgeo Grid; it scans the whole file but does not
keep cell properties (PORO, PERMX).
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _peer  # noqa: E402

import xtgeo  # noqa: E402


def parse(path):
    return xtgeo.grid_from_file(path, fformat="grdecl")


def describe(grid):
    return {"cells": int(grid.ncol * grid.nrow * grid.nlay),
            "parsed": "geometry only (COORD, ZCORN, ACTNUM)"}


if __name__ == "__main__":
    _peer.run("xtgeo grid_from_file", "xtgeo " + xtgeo.__version__, parse, describe)
