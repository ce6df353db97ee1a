#!/usr/bin/env python3
"""Writes a large EGRID + INIT + UNRST set by tiling a real simulation run in I and J.

The source is the Reek model as simulated (res2df test data, 40 x 64 x 14, 35,817 active
cells, 4 report steps). Tile (ti, tj) is the source grid moved by ti times its I edge
vector and tj times its J edge vector (the grid is rotated; the edge vectors are the mean
pillar offsets across the grid), so the tiles pave the plane like the source's cells do.

- EGRID: FILEHEAD, MAPUNITS, MAPAXES, GRIDUNIT, GDORIENT as written; GRIDHEAD with the new
  dimensions; COORD built from the source pillars; ZCORN and ACTNUM tiled in (i, j, k)
  order; ENDGRID. The source's NNC records are left out (they name source cells).
- INIT: the headers (INTEHEAD with the new NX, NY, NZ and active count) and the tables as
  written; of the per-cell arrays only --init (default: 12 common ones), each re-mapped to
  the tiled active cells. NNC-sized arrays (TRANNNC) are left out.
- UNRST: every report step's headers and well arrays as written (INTEHEAD patched as
  above); of the solution arrays only --dynamic (default PRESSURE, SWAT, SGAS), re-mapped.

Files are written as ECLIPSE writes them: big-endian Fortran records, a 16-byte keyword
header record (8-character name, int32 count, 4-character type), data in records of 1000
numbers or 105 strings. Arrays are streamed one K layer at a time, so memory stays at a
few tiled layers whatever the size.

The number of tiles is the smallest near-square count whose EGRID reaches --min-bytes.

    python3 bench/make_tiled_egrid.py OUTDIR [--min-bytes 1e9] [--tiles TI TJ]
        [--source STEM] [--name TILED_REEK]

writes OUTDIR/NAME.EGRID, NAME.INIT and NAME.UNRST.
"""

import argparse
import math
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_SOURCE = os.path.normpath(os.path.join(
    HERE, "..", "..", "shared", "data", "reek", "res2df_sim", "eclipse", "model",
    "2_R001_REEK-0"))
DEFAULT_INIT = ["PORV", "DX", "DY", "DZ", "PERMX", "PERMY", "PERMZ", "PORO", "NTG", "DEPTH",
                "SATNUM", "FIPNUM"]
DEFAULT_DYNAMIC = ["PRESSURE", "SWAT", "SGAS"]

ELEMENT = {"INTE": (4, ">i4"), "REAL": (4, ">f4"), "DOUB": (8, ">f8"), "LOGI": (4, ">i4"),
           "CHAR": (8, None), "MESS": (0, None)}


# ------------------------------------------------------------------------------- reading
class Record:
    __slots__ = ("name", "type", "count", "payload")

    def __init__(self, name, type_, count, payload):
        self.name, self.type, self.count, self.payload = name, type_, count, payload

    def element_size(self):
        if self.type.startswith("C0"):
            return int(self.type[1:])
        return ELEMENT[self.type][0]

    def values(self):
        """Numeric payload as a numpy array (big-endian dtype)."""
        return np.frombuffer(self.payload, dtype=ELEMENT[self.type][1])


def read_records(path):
    """Every record of a small unformatted keyword file, data markers removed."""
    with open(path, "rb") as f:
        raw = f.read()
    out = []
    pos = 0
    while pos < len(raw):
        head = raw[pos:pos + 24]
        if len(head) < 24 or int.from_bytes(head[:4], "big") != 16:
            raise ValueError(f"{path}: bad keyword header at byte {pos}")
        name = head[4:12].decode("ascii").rstrip()
        count = int.from_bytes(head[12:16], "big", signed=True)
        type_ = head[16:20].decode("ascii")
        pos += 24
        rec = Record(name, type_, count, b"")
        size = count * rec.element_size()
        chunks = []
        while size > 0:
            n = int.from_bytes(raw[pos:pos + 4], "big")
            chunks.append(raw[pos + 4:pos + 4 + n])
            if int.from_bytes(raw[pos + 4 + n:pos + 8 + n], "big") != n:
                raise ValueError(f"{path}: {name}: bad record marker at byte {pos}")
            pos += n + 8
            size -= n
        rec.payload = b"".join(chunks)
        out.append(rec)
    return out


# ------------------------------------------------------------------------------- writing
class KeywordStream:
    """One keyword: header written at once, data appended in any pieces, blocked into
    Fortran records of `per_block` elements as they come."""

    def __init__(self, f, name, type_, count):
        self.f = f
        self.name = name
        self.count = count
        self.written = 0
        self.esize = 8 if type_ == "CHAR" else (int(type_[1:]) if type_.startswith("C0")
                                                 else ELEMENT[type_][0])
        self.per_block = 105 if (type_ == "CHAR" or type_.startswith("C0")) else 1000
        self.pending = b""
        header = name.ljust(8).encode("ascii") + int(count).to_bytes(4, "big", signed=True) + \
            type_.encode("ascii")
        marker = (16).to_bytes(4, "big")
        f.write(marker + header + marker)

    def write(self, data):
        """data: bytes or a numpy array already in the file's (big-endian) dtype."""
        raw = np.frombuffer(data if isinstance(data, bytes) else data.tobytes(), dtype=np.uint8)
        if self.pending:
            raw = np.concatenate([np.frombuffer(self.pending, dtype=np.uint8), raw])
        block = self.per_block * self.esize
        full = len(raw) // block
        if full:
            out = np.empty((full, block + 8), dtype=np.uint8)
            marker = np.frombuffer(block.to_bytes(4, "big"), dtype=np.uint8)
            out[:, :4] = marker
            out[:, -4:] = marker
            out[:, 4:-4] = raw[:full * block].reshape(full, block)
            self.f.write(out.data)
        self.pending = raw[full * block:].tobytes()
        self.written += len(raw) // self.esize - len(self.pending) // self.esize

    def close(self):
        if self.pending:
            n = len(self.pending)
            marker = n.to_bytes(4, "big")
            self.f.write(marker + self.pending + marker)
            self.written += n // self.esize
            self.pending = b""
        if self.written != self.count:
            raise AssertionError(f"{self.name}: wrote {self.written} of {self.count} values")


def copy_record(f, rec, payload=None):
    stream = KeywordStream(f, rec.name, rec.type, rec.count)
    if rec.count:
        stream.write(rec.payload if payload is None else payload)
    stream.close()


# ------------------------------------------------------------------------------- tiling
class Tiling:
    def __init__(self, egrid_records, ti, tj):
        by_name = {r.name: r for r in egrid_records}
        head = by_name["GRIDHEAD"].values()
        self.nx, self.ny, self.nz = int(head[1]), int(head[2]), int(head[3])
        self.ti, self.tj = ti, tj
        self.NX, self.NY, self.NZ = self.nx * ti, self.ny * tj, self.nz
        self.actnum = by_name["ACTNUM"].values().astype(np.int32).reshape(self.nz, self.ny, self.nx)
        self.active = self.actnum > 0
        self.nact = int(self.active.sum())
        self.cells = self.nx * self.ny * self.nz
        self.coord = by_name["COORD"].values().astype(np.float64).reshape(self.ny + 1, self.nx + 1, 6)
        self.zcorn = by_name["ZCORN"].values().reshape(self.nz, 2, 2 * self.ny, 2 * self.nx)
        self.nnc = int(by_name["NNC1"].count) if "NNC1" in by_name else -1
        self.tiled_active_layer = np.tile(self.active, (1, tj, ti))  # (nz, NY, NX) bool
        self.tiled_nact = int(self.tiled_active_layer.sum())

    def tiled_coord(self):
        c = self.coord
        # Mean pillar offsets across the grid in I and in J (x, y only).
        ex = (c[:, -1, :] - c[:, 0, :]).mean(axis=0)
        ey = (c[-1, :, :] - c[0, :, :]).mean(axis=0)
        # One shift for the whole pillar (top and bottom alike): tiles are exact translates.
        ex = np.tile([(ex[0] + ex[3]) / 2, (ex[1] + ex[4]) / 2, 0.0], 2)
        ey = np.tile([(ey[0] + ey[3]) / 2, (ey[1] + ey[4]) / 2, 0.0], 2)
        I = np.arange(self.NX + 1)
        tI = np.minimum(I // self.nx, self.ti - 1)
        J = np.arange(self.NY + 1)
        tJ = np.minimum(J // self.ny, self.tj - 1)
        out = c[(J - tJ * self.ny)[:, None], (I - tI * self.nx)[None, :], :]
        out = out + tI[None, :, None] * ex[None, None, :] + tJ[:, None, None] * ey[None, None, :]
        return out.astype(">f4")

    def zcorn_layers(self):
        for k in range(self.nz):
            for t in range(2):
                yield np.tile(self.zcorn[k, t], (self.tj, self.ti))

    def actnum_layers(self):
        for k in range(self.nz):
            yield np.tile(self.actnum[k], (self.tj, self.ti)).astype(">i4")

    def cell_layers(self, values, dtype):
        """Tiles one per-cell or per-active-cell array; yields, per K layer, the values the
        tiled file holds (all cells, or the active ones in cell order)."""
        per_active = len(values) == self.nact and self.nact != self.cells
        full = np.zeros(self.cells, dtype=values.dtype)
        if per_active:
            full[self.active.ravel()] = values
        else:
            full[:] = values
        full = full.reshape(self.nz, self.ny, self.nx)
        for k in range(self.nz):
            layer = np.tile(full[k], (self.tj, self.ti))
            if per_active:
                layer = layer[self.tiled_active_layer[k]]
            yield layer.astype(dtype).ravel()

    def tiled_count(self, count):
        return self.tiled_nact if count == self.nact else self.NX * self.NY * self.NZ

    def is_cell_array(self, rec):
        return rec.type in ("INTE", "REAL", "DOUB", "LOGI") and rec.count in (self.nact, self.cells)

    def patched_intehead(self, rec):
        values = rec.values().copy()
        values[8:12] = [self.NX, self.NY, self.NZ, self.tiled_nact]
        return values


def write_cell_array(f, tiling, rec):
    stream = KeywordStream(f, rec.name, rec.type, tiling.tiled_count(rec.count))
    for layer in tiling.cell_layers(rec.values(), ELEMENT[rec.type][1]):
        stream.write(layer)
    stream.close()


def write_egrid(path, records, tiling):
    with open(path, "wb") as f:
        for rec in records:
            if rec.name in ("NNCHEAD", "NNC1", "NNC2", "NNCL", "NNCG"):
                continue
            if rec.name == "GRIDHEAD":
                values = rec.values().copy()
                values[1:4] = [tiling.NX, tiling.NY, tiling.NZ]
                copy_record(f, rec, values)
            elif rec.name == "COORD":
                stream = KeywordStream(f, "COORD", "REAL", 6 * (tiling.NX + 1) * (tiling.NY + 1))
                stream.write(tiling.tiled_coord())
                stream.close()
            elif rec.name == "ZCORN":
                stream = KeywordStream(f, "ZCORN", "REAL", 8 * tiling.NX * tiling.NY * tiling.NZ)
                for layer in tiling.zcorn_layers():
                    stream.write(layer)
                stream.close()
            elif rec.name == "ACTNUM":
                stream = KeywordStream(f, "ACTNUM", "INTE", tiling.NX * tiling.NY * tiling.NZ)
                for layer in tiling.actnum_layers():
                    stream.write(layer)
                stream.close()
            else:
                copy_record(f, rec)


def write_results(path, records, tiling, keep):
    """INIT or UNRST: headers and small arrays as written, the `keep` cell arrays tiled,
    other cell arrays and NNC-sized arrays left out."""
    with open(path, "wb") as f:
        for rec in records:
            if rec.name == "INTEHEAD":
                copy_record(f, rec, tiling.patched_intehead(rec))
            elif tiling.is_cell_array(rec):
                if rec.name in keep:
                    write_cell_array(f, tiling, rec)
            elif rec.count == tiling.nnc and rec.type != "CHAR":
                continue
            else:
                copy_record(f, rec)


def egrid_bytes(nx, ny, nz):
    def kw(n, esize=4):
        return 24 + n * esize + 8 * math.ceil(n / 1000)
    return kw(6 * (nx + 1) * (ny + 1)) + kw(8 * nx * ny * nz) + kw(nx * ny * nz) + 2000


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("outdir")
    parser.add_argument("--source", default=DEFAULT_SOURCE,
                        help="source STEM (STEM.EGRID, STEM.INIT, STEM.UNRST)")
    parser.add_argument("--name", default="TILED_REEK")
    parser.add_argument("--min-bytes", type=float, default=1e9, help="EGRID size to reach")
    parser.add_argument("--tiles", type=int, nargs=2, metavar=("TI", "TJ"))
    parser.add_argument("--init", nargs="*", default=DEFAULT_INIT)
    parser.add_argument("--dynamic", nargs="*", default=DEFAULT_DYNAMIC)
    args = parser.parse_args()

    egrid_src = read_records(args.source + ".EGRID")
    head = next(r for r in egrid_src if r.name == "GRIDHEAD").values()
    nx, ny, nz = int(head[1]), int(head[2]), int(head[3])
    if args.tiles:
        ti, tj = args.tiles
    else:
        n = 1
        while True:
            ti = math.ceil(math.sqrt(n))
            tj = math.ceil(n / ti)
            if egrid_bytes(nx * ti, ny * tj, nz) >= args.min_bytes:
                break
            n += 1
    tiling = Tiling(egrid_src, ti, tj)
    os.makedirs(args.outdir, exist_ok=True)
    stem = os.path.join(args.outdir, args.name)
    print(f"tiling {args.source} ({nx} x {ny} x {nz}) {ti} x {tj} times: "
          f"{tiling.NX} x {tiling.NY} x {tiling.NZ} = {tiling.NX * tiling.NY * tiling.NZ:,} "
          f"cells, {tiling.tiled_nact:,} active", file=sys.stderr)
    start = time.time()
    try:
        write_egrid(stem + ".EGRID", egrid_src, tiling)
        write_results(stem + ".INIT", read_records(args.source + ".INIT"), tiling,
                      set(args.init))
        write_results(stem + ".UNRST", read_records(args.source + ".UNRST"), tiling,
                      set(args.dynamic))
    except BaseException:
        for ext in (".EGRID", ".INIT", ".UNRST"):
            if os.path.exists(stem + ext):
                os.unlink(stem + ext)
        raise
    for ext in (".EGRID", ".INIT", ".UNRST"):
        print(f"  {stem + ext}: {os.path.getsize(stem + ext):,} bytes", file=sys.stderr)
    print(f"  written in {time.time() - start:.1f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
