"""The 8 corners of every cell, and the cell properties, equal those of OPM (an independent
implementation, Debian's python3-opm-common) for the Reek, Emerald and SPE9 decks.

OPM has no corner API for decks: its own EGRID writer and reader (EclOutput / EGrid, which
stores COORD/ZCORN as float32 as the EGRID format does) gives the corners, so corners agree
to float32 rounding. Properties are compared value for value with OPM's raw deck arrays.
"""
import os
import tempfile

import numpy as np
from opm.io.ecl_state import EclipseState

import resmr_testing as rt
from opm_testing import corner_error, opm_corners, opm_deck, our_corners

args = rt.arguments()
rt.load_plugin(args.plugin)
DATA = args.data
work = tempfile.mkdtemp(prefix="resmr-opm-", dir=args.temp)

HEXAHEDRON_FACES = np.array([[0, 4, 7, 3], [1, 2, 6, 5], [0, 1, 5, 4], [3, 7, 6, 2],
                             [0, 3, 2, 1], [4, 5, 6, 7]])


def signed_volumes(points, hexahedra):
    """Signed volume of each VTK hexahedron by the divergence theorem over its faces split
    at their centres: exact for planar faces and robust for the pinched corners that make
    VTK's tetrahedra-based cell sizes negative."""
    corners = points[hexahedra]  # (cells, 8, 3)
    centre = corners.mean(axis=1)
    volume = np.zeros(len(corners))
    for face in HEXAHEDRON_FACES:
        quad = corners[:, face]
        face_centre = quad.mean(axis=1)
        for a in range(4):
            x = quad[:, a] - centre
            y = quad[:, (a + 1) % 4] - centre
            volume += np.einsum("ij,ij->i", np.cross(x, y), face_centre - centre) / 6.0
    return volume


def check_volumes_positive(grid, name):
    volume = signed_volumes(*rt.points_and_cells(grid))
    negative = int((volume < -1e-9 * np.abs(volume).max()).sum())
    if negative:
        rt.fail(f"{name}: {negative} cells have negative volume")
    print(f"{name}: {int((volume > 0).sum())} cells with positive volume, none negative")


def compare_corners(name, path, opm_path, dims, extra_keywords=(), properties=()):
    reader, grid = rt.read_grid(path, ApplyMapAxes=0)
    deck = opm_deck(opm_path, extra_keywords)
    reference = opm_corners(deck, dims, name, work)
    ours, mirrored = our_corners(grid, dims)
    # OPM's corners come from float32 COORD/ZCORN: allow a few float32 ulps of the extent.
    error, tolerance = corner_error(ours, reference)
    print(f"{name}: max corner difference x {error[0]:.3g} y {error[1]:.3g} z {error[2]:.3g}"
          f" (tolerance {tolerance.round(6)}), stored k-mirrored: {mirrored}")
    if np.any(error > tolerance):
        worst = np.unravel_index(np.abs(ours - reference).max(axis=2).argmax(), ours.shape[:2])
        rt.fail(f"{name}: corners differ from OPM, worst at cell {worst[0]} corner {worst[1]}:"
                f" ours {ours[worst]} OPM {reference[worst]}")
    check_volumes_positive(grid, name)
    nx, ny, nz = dims
    i = rt.cell_array(grid, "I") - 1
    j = rt.cell_array(grid, "J") - 1
    k = rt.cell_array(grid, "K") - 1
    eclipse_cell = (k * ny + j) * nx + i
    for keyword in properties:
        ours_values = np.empty(nx * ny * nz)
        ours_values[eclipse_cell] = rt.cell_array(grid, keyword)
        if keyword.endswith("NUM") or keyword == "FACIES":
            theirs = np.asarray(deck[keyword].get_int_array(), np.float64)
        else:
            theirs = np.asarray(deck[keyword].get_raw_array(), np.float64)
        differing = int((ours_values != theirs).sum())
        if differing:
            rt.fail(f"{name}: {keyword} differs from OPM in {differing} cells")
        print(f"{name}: {keyword} equal value for value ({theirs.size} cells)")
    return reader, grid, deck


# Reek: faulted, with INCLUDE files, MAPAXES and edited arrays.
reek = os.path.join(DATA, "reek/res2df_sim/eclipse/model/2_R001_REEK-0.DATA")
compare_corners("Reek", reek, reek, (40, 64, 14), properties=("PORO", "PERMX", "FIPNUM", "EQLNUM"))

# Emerald: left-handed, with a hole of inactive cells. OPM needs a RUNSPEC wrapper and to be
# told about FACIES.
emerald = os.path.join(DATA, "emerald/eme_small_w_hole_grid_params.grdecl")
wrapper = os.path.join(work, "EMERALD.DATA")
with open(wrapper, "w") as handle:
    handle.write(f"RUNSPEC\nDIMENS\n 21 41 18 /\nOIL\nWATER\nMETRIC\nGRID\nINCLUDE\n '{emerald}' /\n")
facies = '{"name":"FACIES","sections":["GRID"],"data":{"value_type":"INT"}}'
compare_corners("Emerald", emerald, wrapper, (21, 41, 18), extra_keywords=[facies],
                properties=("PORO", "FACIES"))

# SPE9 corner-point version, then the Cartesian deck (DX/DY/DZ/TOPS): OPM's EclipseGrid
# gives cell volumes and centre depths (SI units; the deck is in feet).
spe9_cp = os.path.join(DATA, "spe9/opm-data_deck/SPE9_CP.DATA")
compare_corners("SPE9_CP", spe9_cp, spe9_cp, (24, 25, 15), properties=("PORO", "PERMX"))

spe9 = os.path.join(DATA, "spe9/opm-data_deck/SPE9.DATA")
reader, grid = rt.read_grid(spe9)
state = EclipseState(opm_deck(spe9))
opm_grid = state.grid()
feet = 0.3048
ours, _ = our_corners(grid, (24, 25, 15))
depth = ours[:, :, 2].mean(axis=1) * feet
volume = ((ours[:, 1, 0] - ours[:, 0, 0]) * (ours[:, 2, 1] - ours[:, 0, 1]) *
          (ours[:, 4, 2] - ours[:, 0, 2])) * feet ** 3
reference_depth = np.array(opm_grid.getCellDepth())
reference_volume = np.array(opm_grid.getCellVolume())
depth_error = np.abs(depth - reference_depth).max()
volume_error = (np.abs(volume - reference_volume) / reference_volume).max()
print(f"SPE9 Cartesian: max depth difference {depth_error:.3g} m, max relative volume"
      f" difference {volume_error:.3g}")
if depth_error > 1e-6 or volume_error > 1e-9:
    rt.fail("SPE9 Cartesian grid differs from OPM's EclipseGrid")
check_volumes_positive(grid, "SPE9")
print("PASS")
