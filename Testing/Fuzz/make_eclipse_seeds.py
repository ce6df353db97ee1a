#!/usr/bin/env python3
"""Writes the ECLIPSE output seeds of the FuzzEclipseOutput corpus (EGRID, INIT, restarts).

Unformatted files: Fortran sequential records, big-endian; each keyword is a 16-byte header
record (8-character name, int32 count, 4-character type) followed by data records of at
most 1000 numbers / 105 strings, every record framed by int32 byte counts. Formatted files:
" 'NAME    '  count 'TYPE'" lines then the values.

A seed holds up to 8 files joined by the marker b"%RESMR%\\n" (see FuzzEclipseOutput.cpp):
grid, INIT, then one unified restart (3 parts) or several per-step restarts (Xnnnn).
Run from anywhere: python3 make_eclipse_seeds.py [OUTPUT_DIR] (default: seeds/ beside it).
"""
import os
import struct
import sys

SPLIT = b"%RESMR%\n"
FORMATS = {"INTE": ">i", "REAL": ">f", "DOUB": ">d", "LOGI": ">i"}


def record(payload):
    return struct.pack(">i", len(payload)) + payload + struct.pack(">i", len(payload))


def keyword(name, kind, values, block=None):
    """One unformatted keyword; kind INTE/REAL/DOUB/LOGI/CHAR/C0nn/MESS."""
    out = record(name.ljust(8).encode() + struct.pack(">i", len(values)) + kind.encode())
    if kind == "MESS":
        return out
    strings = kind == "CHAR" or kind.startswith("C0")
    width = 8 if kind == "CHAR" else int(kind[1:]) if strings else 0
    block = block or (105 if strings else 1000)
    for start in range(0, len(values), block):
        chunk = values[start:start + block]
        if strings:
            payload = b"".join(v.ljust(width).encode() for v in chunk)
        else:
            payload = b"".join(struct.pack(FORMATS[kind], v) for v in chunk)
        out += record(payload)
    return out


def formatted(name, kind, values):
    """One formatted keyword, laid out as ECLIPSE writes it (values several per line)."""
    out = " '%-8s' %11d '%s'\n" % (name, len(values), kind)
    if kind == "CHAR" or kind.startswith("C0"):
        items = ["'%-8s'" % v for v in values]
        per_line = 7
    elif kind in ("INTE",):
        items = ["%d" % v for v in values]
        per_line = 6
    elif kind == "LOGI":
        items = ["T" if v else "F" for v in values]
        per_line = 25
    elif kind == "DOUB":
        items = [("%.14E" % v).replace("E", "D") for v in values]
        per_line = 3
    else:
        items = ["%.8E" % v for v in values]
        per_line = 4
    for start in range(0, len(items), per_line):
        out += " " + " ".join(items[start:start + per_line]) + "\n"
    return out.encode()


def grid_arrays(nx, ny, nz):
    coord = []
    for j in range(ny + 1):
        for i in range(nx + 1):
            coord += [float(i), float(j), 1000.0, float(i), float(j), 1000.0 + nz]
    zcorn = []
    for k in range(nz):
        for top_or_bottom in (0, 1):
            zcorn += [1000.0 + k + top_or_bottom] * (4 * nx * ny)
    return coord, zcorn


def gridhead(nx, ny, nz, lgr=0):
    head = [0] * 100
    head[0:5] = [1, nx, ny, nz, lgr]
    return head


def filehead(dual=0):
    head = [0] * 100
    head[0:7] = [3, 2007, 0, 0, 0, dual, 0]
    return head


def egrid(nx, ny, nz, actnum=None, write=keyword, dual=0, extra=b""):
    coord, zcorn = grid_arrays(nx, ny, nz)
    out = (write("FILEHEAD", "INTE", filehead(dual))
           + write("MAPUNITS", "CHAR", ["METRES"])
           + write("MAPAXES", "REAL", [0.0, 1.0, 0.0, 0.0, 1.0, 0.0])
           + write("GRIDUNIT", "CHAR", ["METRES", ""])
           + write("GRIDHEAD", "INTE", gridhead(nx, ny, nz))
           + write("COORD", "REAL", coord)
           + write("ZCORN", "REAL", zcorn))
    if actnum is not None:
        out += write("ACTNUM", "INTE", actnum)
    return out + write("ENDGRID", "INTE", []) + extra


def intehead(active, date=(1, 1, 2000)):
    head = [0] * 95
    head[11] = active
    head[64], head[65], head[66] = date
    return head


def init_file(active, write=keyword):
    return (write("INTEHEAD", "INTE", intehead(active))
            + write("LOGIHEAD", "LOGI", [1, 0, 1])
            + write("DOUBHEAD", "DOUB", [0.0, 1.5])
            + write("PORV", "REAL", [100.0 * (c + 1) for c in range(active)])
            + write("PORO", "REAL", [0.2] * active)
            + write("PERMX", "DOUB", [150.0] * active)
            + write("SATNUM", "INTE", [1] * active)
            + write("TABDIMS", "INTE", [7] * active))


def restart_step(report, active, days, write=keyword, seqnum=True):
    out = write("SEQNUM", "INTE", [report]) if seqnum else b""
    return (out
            + write("INTEHEAD", "INTE", intehead(active, (1 + report, 1, 2000)))
            + write("LOGIHEAD", "LOGI", [0] * 3)
            + write("DOUBHEAD", "DOUB", [days, 0.0])
            + write("STARTSOL", "MESS", [])
            + write("PRESSURE", "REAL", [200.0 + report] * active)
            + write("SWAT", "REAL", [0.1 * report] * active)
            + write("SGAS", "DOUB", [0.0] * active)
            + write("ENDSOL", "MESS", [])
            + write("HIDDEN", "INTE", [1] * active))


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "seeds")
    os.makedirs(out_dir, exist_ok=True)
    seeds = {}

    # EGRID alone: FILEHEAD, MAPUNITS, MAPAXES, GRIDUNIT, GRIDHEAD, COORD, ZCORN, ACTNUM,
    # ENDGRID, NNCHEAD/NNC1/NNC2 of the global grid.
    seeds["eclipse_2x1x1.EGRID"] = egrid(2, 1, 1, [1, 0], extra=(
        keyword("NNCHEAD", "INTE", [1, 0] + [0] * 8)
        + keyword("NNC1", "INTE", [1]) + keyword("NNC2", "INTE", [2])))

    # Grid, INIT and a unified restart of two steps; one inactive cell of three.
    seeds["eclipse_3x1x1_init_unrst.bin"] = SPLIT.join([
        egrid(3, 1, 1, [1, 0, 1]),
        init_file(2),
        restart_step(1, 2, 10.0) + restart_step(2, 2, 20.0)])

    # Grid, no INIT, per-step restarts X0000/X0001 (no SEQNUM: steps start at INTEHEAD).
    seeds["eclipse_1x1x2_xnnnn.bin"] = SPLIT.join([
        egrid(1, 1, 2),
        b"",
        restart_step(0, 2, 0.0, seqnum=False),
        restart_step(1, 2, 31.0)])

    # Formatted FEGRID + FINIT + FUNRST.
    seeds["eclipse_2x1x1_formatted.bin"] = SPLIT.join([
        egrid(2, 1, 1, [1, 1], write=formatted),
        init_file(2, write=formatted),
        restart_step(1, 2, 5.0, write=formatted)])

    # Dual porosity: FILEHEAD(6) = 1, ACTNUM 1 matrix, 2 fracture, 3 both; INIT arrays per
    # active matrix + fracture cell, and per cell and porosity.
    seeds["eclipse_dualporo.bin"] = SPLIT.join([
        egrid(2, 1, 1, [3, 1], dual=1),
        keyword("INTEHEAD", "INTE", intehead(3)) + keyword("PORO", "REAL", [0.1, 0.2, 0.3])
        + keyword("PERMX", "REAL", [1.0, 2.0, 3.0, 4.0]),
        b""])

    # A local grid after the global one (LGR ... ENDLGR), and an INIT with an LGR section.
    lgr_coord, lgr_zcorn = grid_arrays(2, 2, 1)
    seeds["eclipse_lgr.bin"] = SPLIT.join([
        egrid(1, 1, 1, extra=(
            keyword("LGR", "CHAR", ["LGR1"])
            + keyword("GRIDHEAD", "INTE", gridhead(2, 2, 1, 1))
            + keyword("COORD", "REAL", lgr_coord) + keyword("ZCORN", "REAL", lgr_zcorn)
            + keyword("HOSTNUM", "INTE", [1] * 4)
            + keyword("ENDGRID", "INTE", []) + keyword("ENDLGR", "INTE", []))),
        keyword("INTEHEAD", "INTE", intehead(1)) + keyword("PORO", "REAL", [0.3])
        + keyword("LGR", "CHAR", ["LGR1"]) + keyword("PORO", "REAL", [0.1] * 4)
        + keyword("LGRSGONE", "MESS", [])])

    # Keyword-file corner cases: non-standard block sizes (walked), C0nn strings, MESS,
    # an empty record, LOGI, DOUB split over records.
    seeds["eclipse_records.bin"] = (
        keyword("INTEHEAD", "INTE", list(range(12)), block=5)
        + keyword("NAMES", "C012", ["PRESSURE", "A LONG NAME"])
        + keyword("WELLS", "CHAR", ["OP_1", "INJ"], block=1)
        + keyword("STARTSOL", "MESS", [])
        + keyword("EMPTY", "REAL", [])
        + keyword("FLAGS", "LOGI", [1, 0, 1])
        + keyword("DOUBHEAD", "DOUB", [1.0, 2.0, 3.0], block=2))

    # Truncated EGRID: ZCORN's data record ends early.
    seeds["eclipse_truncated.EGRID"] = egrid(1, 1, 1)[:-60]

    total = 0
    for name, data in seeds.items():
        with open(os.path.join(out_dir, name), "wb") as f:
            f.write(data)
        total += len(data)
        print(name, len(data), "bytes")
    print("total", total, "bytes")


if __name__ == "__main__":
    main()
