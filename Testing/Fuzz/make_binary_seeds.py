#!/usr/bin/env python3
"""Writes the binary GRDECL seeds of the fuzz corpus (Fortran sequential records, big-endian).

Each keyword is a 16-byte header record (8-character name, int32 count, 4-character type)
followed by data records of at most 1000 elements, every record framed by int32 byte counts.
Run from anywhere: python3 make_binary_seeds.py [OUTPUT_DIR] (default: seeds/ beside it).
"""
import os
import struct
import sys

FORMATS = {"INTE": ">i", "REAL": ">f", "DOUB": ">d", "LOGI": ">i", "CHAR": "8s"}


def record(payload):
    return struct.pack(">i", len(payload)) + payload + struct.pack(">i", len(payload))


def keyword(name, kind, values, block=1000):
    out = record(name.ljust(8).encode() + struct.pack(">i", len(values)) + kind.encode())
    fmt = FORMATS[kind]
    for start in range(0, len(values), block):
        chunk = values[start:start + block]
        if kind == "CHAR":
            payload = b"".join(v.ljust(8).encode() for v in chunk)
        else:
            payload = b"".join(struct.pack(fmt, v) for v in chunk)
        out += record(payload)
    return out


def grid(nx, ny, nz, kind="REAL"):
    coord = []
    for j in range(ny + 1):
        for i in range(nx + 1):
            coord += [float(i), float(j), 1000.0, float(i), float(j), 1000.0 + nz]
    zcorn = []
    for k in range(nz):
        for top_or_bottom in (0, 1):
            zcorn += [1000.0 + k + top_or_bottom] * (4 * nx * ny)
    return (keyword("COORD", kind, coord), keyword("ZCORN", kind, zcorn))


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "seeds")
    os.makedirs(out_dir, exist_ok=True)
    seeds = {}

    coord, zcorn = grid(2, 1, 1)
    seeds["binary_2x1x1.bgrdecl"] = (
        keyword("GRIDUNIT", "CHAR", ["METRES", ""])
        + keyword("SPECGRID", "INTE", [2, 1, 1, 1])
        + keyword("MAPAXES", "REAL", [0.0, 1.0, 0.0, 0.0, 1.0, 0.0])
        + coord + zcorn
        + keyword("ACTNUM", "INTE", [1, 0])
        + keyword("PORO", "REAL", [0.2, 0.3])
        + keyword("FLAGS", "LOGI", [1, 0])
        + keyword("SKIPPED", "INTE", [1, 2, 3]))

    # ZCORN of 8*6*5*5 = 1200 doubles: two data records (1000 + 200).
    coord, zcorn = grid(6, 5, 5, "DOUB")
    seeds["binary_6x5x5_doub.bgrdecl"] = keyword("DIMENS", "INTE", [6, 5, 5]) + coord + zcorn

    # A truncated file: the ZCORN data record ends early.
    coord, zcorn = grid(1, 1, 1)
    seeds["binary_truncated.bgrdecl"] = (
        keyword("SPECGRID", "INTE", [1, 1, 1, 1]) + coord + zcorn[:-10])

    for name, data in seeds.items():
        with open(os.path.join(out_dir, name), "wb") as f:
            f.write(data)
        print(name, len(data), "bytes")


if __name__ == "__main__":
    main()
