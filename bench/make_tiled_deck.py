#!/usr/bin/env python3
"""Writes a large ASCII GRDECL deck by tiling a real corner-point grid in I and J.

The source is the Reek grid (40 x 64 x 14, xtgeo test data) with its porosity and faults.
Tile (ti, tj) is the source grid shifted by ti times its I extent and tj times its J
extent; ZCORN, ACTNUM, PORO and the FAULTS records repeat per tile, PERMX is derived
from PORO. Formatting follows real exports: COORD and ZCORN with 3 decimals, 6 per line;
ACTNUM as N*value runs; PORO with 6 decimals; PERMX with 3 decimals.

The deck is streamed to disk (memory stays at a few source-grid-sized rows), and the
number of tiles is the smallest near-square count whose file reaches --min-bytes.

    python3 bench/make_tiled_deck.py OUT.grdecl [--min-bytes 1e9] [--tiles TI TJ]
"""

import argparse
import math
import os
import re
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_DATA = os.path.normpath(os.path.join(HERE, "..", "..", "shared", "data", "reek",
                                             "xtgeo_testdata"))


# ------------------------------------------------------------------------------- reading
def read_keywords(path, wanted):
    """Minimal GRDECL reader for the small source files: {keyword: list of tokens}."""
    out = {}
    current = None
    with open(path) as f:
        for line in f:
            line = line.split("--", 1)[0]
            if not line.strip():
                continue
            if current is None:
                word = line.split()[0] if line.split() else ""
                if word in ("ECHO", "NOECHO"):
                    continue
                if re.match(r"^[A-Z][A-Z0-9_]{0,7}$", word) and line[0] != " ":
                    current = word
                    out.setdefault(current, [])
                    rest = line.split(None, 1)[1] if len(line.split()) > 1 else ""
                    line = rest
                else:
                    continue
            if "/" in line and current not in ("FAULTS",):
                line = line.split("/", 1)[0]
                out[current].extend(line.split())
                current = None
            elif current == "FAULTS":
                stripped = line.strip()
                if stripped == "/":
                    current = None
                elif stripped:
                    out[current].append(stripped)
            else:
                out[current].extend(line.split())
    return {k: v for k, v in out.items() if k in wanted}


def expand(tokens, dtype=float):
    values = []
    for t in tokens:
        if "*" in t:
            n, v = t.split("*", 1)
            values.extend([v] * int(n))
        else:
            values.append(t)
    return np.array(values, dtype=dtype)


# ------------------------------------------------------------------------------- writing
class LineWriter:
    """Writes numbers `per_line` to a line, across calls (rows need not fill lines)."""

    def __init__(self, f, fmt, per_line):
        self.f = f
        self.fmt = fmt
        self.per_line = per_line
        self.line_fmt = fmt * per_line + "\n"
        self.carry = np.empty(0)

    def write(self, values):
        values = np.concatenate([self.carry, np.asarray(values, dtype=float)])
        full = (len(values) // self.per_line) * self.per_line
        if full:
            lines = values[:full].reshape(-1, self.per_line)
            self.f.write("".join(self.line_fmt % tuple(row) for row in lines.tolist()))
        self.carry = values[full:]

    def close(self):
        if len(self.carry):
            self.f.write((self.fmt * len(self.carry)) % tuple(self.carry.tolist()) + "\n")
        self.carry = np.empty(0)


def write_runs(f, values, per_line=16):
    """ACTNUM-style integers as N*value runs."""
    values = np.asarray(values, dtype=np.int64)
    change = np.flatnonzero(np.diff(values)) + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change, [len(values)]])
    tokens = [("%d*%d" % (e - s, values[s])) if e - s > 1 else str(values[s])
              for s, e in zip(starts.tolist(), ends.tolist())]
    for i in range(0, len(tokens), per_line):
        f.write(" " + " ".join(tokens[i:i + per_line]) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("output")
    parser.add_argument("--data", default=DEFAULT_DATA, help="folder of the Reek test data")
    parser.add_argument("--min-bytes", type=float, default=1.0e9)
    parser.add_argument("--tiles", type=int, nargs=2, metavar=("TI", "TJ"),
                        help="tile counts (default: smallest near-square reaching --min-bytes)")
    args = parser.parse_args()

    grid = read_keywords(os.path.join(args.data, "reek_sim_grid.grdecl"),
                         {"SPECGRID", "COORD", "ZCORN", "ACTNUM"})
    poro_kw = read_keywords(os.path.join(args.data, "reek_sim_poro.grdecl"), {"PORO"})
    faults = read_keywords(os.path.join(args.data, "reek_sim_faults.grdecl"),
                           {"FAULTS"}).get("FAULTS", [])
    nx, ny, nz = (int(v) for v in grid["SPECGRID"][:3])
    coord = expand(grid["COORD"]).reshape(ny + 1, nx + 1, 6)
    zcorn = expand(grid["ZCORN"]).reshape(2 * nz, 2 * ny, 2 * nx)
    actnum = expand(grid["ACTNUM"], np.int64).reshape(nz, ny, nx)
    poro = expand(poro_kw["PORO"]).reshape(nz, ny, nx)
    # A plausible permeability from porosity (mD), so PERMX has realistic varied digits.
    permx = np.round(10.0 ** (poro * 18.0 - 0.5), 3)

    # Bytes per tile, measured on one formatted tile, to choose the tiling.
    cells_per_tile = nx * ny * nz
    permx_bytes = sum(len(" %.3f" % v) for v in permx.ravel().tolist())
    per_tile = (zcorn.size * (12 + 1 / 6) + cells_per_tile * (9 + 1 / 6) + permx_bytes
                + cells_per_tile / 6 + sum(len(s) + 12 for s in faults))
    if args.tiles:
        ti, tj = args.tiles
    else:
        needed = math.ceil(args.min_bytes * 1.01 / per_tile)
        ti = tj = math.ceil(math.sqrt(needed))
        while (ti - 1) * tj >= needed:
            ti -= 1
    NX, NY = nx * ti, ny * tj
    print(f"source {nx}x{ny}x{nz}, tiles {ti}x{tj} -> {NX}x{NY}x{nz} = {NX * NY * nz} cells",
          file=sys.stderr)

    shift_i = coord[0, nx, :] - coord[0, 0, :]
    shift_j = coord[ny, 0, :] - coord[0, 0, :]
    shift_i[[2, 5]] = 0.0
    shift_j[[2, 5]] = 0.0

    with open(args.output, "w", buffering=1 << 22) as f:
        f.write("-- Generated by bench/make_tiled_deck.py: Reek grid (xtgeo test data) tiled "
                f"{ti} x {tj} in I x J.\n-- {NX} x {NY} x {nz} cells. Benchmark input, not a "
                "real field.\n\nNOECHO\n\nMAPUNITS\n'METRES  ' /\n\nGRIDUNIT\n'METRES  ' "
                "'        ' /\n\n")
        f.write(f"SPECGRID\n  {NX}  {NY}  {nz}   1  F  /\n\n")
        f.write("GDORIENT\nINC INC INC DOWN RIGHT /\n\n")

        f.write("COORD\n")
        w = LineWriter(f, " %12.3f", 6)
        for J in range(NY + 1):
            tyj = min(J // ny, tj - 1)
            j = J - tyj * ny
            row = np.empty((NX + 1, 6))
            for t in range(ti):
                row[t * nx:(t + 1) * nx] = coord[j, :nx] + t * shift_i + tyj * shift_j
            row[NX] = coord[j, nx] + (ti - 1) * shift_i + tyj * shift_j
            w.write(row.ravel())
        w.close()
        f.write("/\n\n")

        f.write("ZCORN\n")
        w = LineWriter(f, " %11.3f", 6)
        for kk in range(2 * nz):
            for t in range(tj):
                for jj in range(2 * ny):
                    w.write(np.tile(zcorn[kk, jj], ti))
        w.close()
        f.write("/\n\n")

        f.write("ACTNUM\n")
        big = np.tile(actnum, (1, tj, ti))
        write_runs(f, big.ravel())
        f.write("/\n\n")

        for name, values, fmt, per_line in (("PORO", poro, " %.6f", 6),
                                            ("PERMX", permx, " %.3f", 6)):
            f.write(f"{name}\n")
            w = LineWriter(f, fmt, per_line)
            for k in range(nz):
                w.write(np.tile(values[k], (tj, ti)).ravel())
            w.close()
            f.write("/\n\n")

        f.write("FAULTS\n-- NAME  IX1 IX2  IY1 IY2  IZ1 IZ2  FACE\n")
        for t_j in range(tj):
            for t_i in range(ti):
                for rec in faults:
                    parts = rec.replace("/", " ").split()
                    name = parts[0].strip("'")
                    i1, i2, j1, j2, k1, k2 = (int(v) for v in parts[1:7])
                    f.write(f"'{name}_{t_i}_{t_j}' {i1 + t_i * nx} {i2 + t_i * nx} "
                            f"{j1 + t_j * ny} {j2 + t_j * ny} {k1} {k2} {parts[7]} /\n")
        f.write("/\n\nECHO\n")

    size = os.path.getsize(args.output)
    print(f"wrote {args.output}: {size} bytes ({size / 1e9:.3f} GB)", file=sys.stderr)
    if not args.tiles and size < args.min_bytes:
        sys.exit(f"deck is {size} bytes, less than --min-bytes {args.min_bytes:.0f}")


if __name__ == "__main__":
    main()
