"""OPM (Debian's python3-opm-common) as an independent reference for decks: parsing, and the
corners of a deck's cells through OPM's own EGRID writer and reader (OPM has no corner API
for decks; EGRID stores COORD/ZCORN as float32, so corners agree to float32 rounding)."""
import os

import numpy as np
from opm.io.ecl import EclOutput, EGrid
from opm.io.parser import Parser

import resmr_testing as rt

# ECLIPSE corner (di + 2 dj + 4 dk) of each VTK hexahedron point.
ECLIPSE_CORNER_OF_VTK_POINT = np.array([0, 1, 3, 2, 4, 5, 7, 6])


def opm_deck(path, extra_keywords=()):
    parser = Parser()
    for keyword in extra_keywords:
        parser.add_keyword(keyword)
    return parser.parse(path)


def opm_corners(deck, dims, name, work):
    """Corners (cells, 8, 3) of the deck's COORD/ZCORN in ECLIPSE cell and corner order."""
    nx, ny, nz = dims
    header = np.zeros(100, np.int32)
    header[0] = 1
    header[1:4] = dims
    egrid_path = os.path.join(work, name + ".EGRID")
    out = EclOutput(egrid_path)
    out.write("FILEHEAD", np.zeros(100, np.int32))
    out.write("GRIDHEAD", header)
    out.write("COORD", np.asarray(deck["COORD"].get_raw_array(), np.float32))
    out.write("ZCORN", np.asarray(deck["ZCORN"].get_raw_array(), np.float32))
    out.write("ACTNUM", np.ones(nx * ny * nz, np.int32))
    out.write("ENDGRID", np.zeros(0, np.int32))
    del out
    grid = EGrid(egrid_path)
    corners = np.zeros((nx * ny * nz, 8, 3))
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                x, y, z = grid.xyz_from_ijk(i, j, k)
                corners[(k * ny + j) * nx + i] = np.column_stack([x, y, z])
    return corners


def our_corners(grid, dims):
    """Our corners as (cells, 8, 3) in ECLIPSE cell and corner order, depth positive."""
    nx, ny, nz = dims
    points, hexahedra = rt.points_and_cells(grid)
    i = rt.cell_array(grid, "I") - 1
    j = rt.cell_array(grid, "J") - 1
    k = rt.cell_array(grid, "K") - 1
    mirrored = nz > 1 and k[0] == nz - 1
    corner_of_point = ECLIPSE_CORNER_OF_VTK_POINT ^ (4 if mirrored else 0)
    eclipse_cell = (k * ny + j) * nx + i
    corners = np.zeros((nx * ny * nz, 8, 3))
    corners[eclipse_cell[:, None], corner_of_point[None, :]] = points[hexahedra]
    corners[..., 2] *= -1.0  # back to depth
    return corners, mirrored


def corner_error(ours, reference):
    """Largest corner difference per axis, and the float32 tolerance for it."""
    scale = np.abs(reference).max(axis=(0, 1))
    tolerance = 4 * np.finfo(np.float32).eps * scale
    return np.abs(ours - reference).max(axis=(0, 1)), tolerance
