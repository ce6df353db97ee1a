"""Peers of `resmr synth` for writing a model of the same size to EGRID, run one process per
measurement: xtgeo (create_box_grid, to_file egrid, and a PORO property to GRDECL)
and resdata (Grid.create_rectangular + save_EGRID). Neither generates geology: they write a
plain box, so they show what writing an EGRID of that size costs in the tools engineers use.

usage: python synth_write_peers.py TOOL NX NY NZ OUT.EGRID   (prints one JSON line)
"""
import json
import resource
import sys
import time

tool, nx, ny, nz, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), sys.argv[5]
if tool == "xtgeo":
    import numpy as np
    import xtgeo
elif tool == "resdata":
    import warnings
    warnings.simplefilter("ignore")
    from resdata.grid import Grid
start = time.perf_counter()  # imports are not counted
if tool == "xtgeo":
    grid = xtgeo.create_box_grid((nx, ny, nz), increment=(50.0, 50.0, 2.0))
    poro = xtgeo.GridProperty(grid, name="PORO", values=np.full((nx, ny, nz), 0.2, dtype=np.float32))
    grid.to_file(out, fformat="egrid")
    poro.to_file(out[:-5] + "PORO.GRDECL", fformat="grdecl")
elif tool == "resdata":
    grid = Grid.create_rectangular((nx, ny, nz), (50.0, 50.0, 2.0))
    grid.save_EGRID(out)
else:
    sys.exit(f"unknown tool {tool}")
seconds = time.perf_counter() - start
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
print(json.dumps({"tool": tool, "dims": [nx, ny, nz], "seconds": seconds,
                  "cells_per_minute": nx * ny * nz / seconds * 60, "peak_rss_mb": peak}))
