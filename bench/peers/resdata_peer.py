#!/usr/bin/env python3
"""Peer: resdata (PyPI, Equinor's former libecl) grid import from GRDECL.

    bench/scratch/venv/bin/python bench/peers/resdata_peer.py DECK

resdata.grid.Grid.load_from_grdecl reads SPECGRID, ZCORN, COORD, ACTNUM (and MAPAXES if
present) with its C keyword reader and builds the grid; it does not keep cell properties.
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _peer  # noqa: E402

import resdata  # noqa: E402
from resdata.grid import Grid  # noqa: E402


def parse(path):
    return Grid.load_from_grdecl(path)


def describe(grid):
    return {"cells": int(grid.get_global_size()),
            "parsed": "geometry only (SPECGRID, ZCORN, COORD, ACTNUM)"}


if __name__ == "__main__":
    _peer.run("resdata Grid.load_from_grdecl", "resdata " + resdata.__version__, parse,
              describe)
