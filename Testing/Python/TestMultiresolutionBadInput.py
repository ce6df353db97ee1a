"""Damaged .resmr and .resmrp files through the multiresolution reader and the Multiresolution
Surface representation (issue 7 point 6). Each case is opened as File > Open does, shown with
the Multiresolution Surface, coloured by PORO when listed, and rendered twice (full detail,
waiting for loads), in its own pvpython process with a time limit of TIMEOUT_S: it must end
normally (no crash, no hang), with a clear error naming the file, and where known the place,
in the reader's or the representation's LastError and once in VTK's error output; and it must
draw what it still can. The good file is drawn first, for the pixels it covers.

Cases, from a small synthetic model built with its properties:
- truncated: the .resmr cut in the middle of its region chunks: refused by the reader (no
  index trailer), nothing drawn;
- garbage header: the first 256 bytes random: refused (bad magic at byte 0);
- damaged header: the magic kept, 16 header bytes changed: refused (header checksum);
- damaged index: a byte of the region index changed: refused (index checksum);
- empty: a .resmr of zero bytes: refused (too short);
- missing file, a folder named .resmr: refused (cannot open, not a regular file);
- truncated .resmrp, empty .resmrp: a good .resmr beside a property file cut in the middle or
  of zero bytes: refused by the reader naming the property file, as a property file of
  another geometry is (Multiresolution.Reader): nothing is drawn;
- missing .resmrp: no error, no property listed, the geometry draws in the solid colour;
- damaged region chunk: a byte of a finest-level region's mesh changed: the file opens
  (chunks are checked when read); the loader refuses that region naming the file, the region
  and the byte; its ancestor stands in: the model covers as many pixels as the good one,
  coloured by PORO;
- damaged root chunk: the same in a root region: named likewise; the other root still draws;
- damaged hash chunk: a byte of the perfect hash's offset table changed: the loader names the
  file and the table; the geometry draws in the solid colour (no cell can be looked up);
- damaged wall depth table: a byte of the wall depth table changed: a warning names the file
  and the table; the model draws coloured by PORO, walls painted from their coordinates;
- damaged property table: a byte of PORO's packed table changed in the .resmrp: the
  representation names the property file and PORO; the geometry draws in the solid colour;
- cut while open: the .resmr cut in place after the roots loaded: the loader names the file
  (cut or rewritten in place) instead of reading past its end (SIGBUS before); the roots
  still draw;
- flat lattice: the .resmr's depth lattice step set to 0.0 and its header CRC recomputed (no
  damage, nonsense): refused naming the field, nothing drawn (drawn flat before);
- .resmrp of 0 tables: the property file's table count set to 0 and its header CRC
  recomputed: refused naming the property file and the field (opened with no properties
  before)."""
import json
import os
import random
import shutil
import struct
import subprocess
import sys
import zlib

CHILD = "--child" in sys.argv
TIMEOUT_S = 120
SIZE = [320, 240]


def child(plugin, path, property_name, image, cut):
    """Opens, shows and renders `path`; prints one RESULT line of JSON. With `cut` = "cut",
    renders the roots first, then cuts the file in place to half its size."""
    import numpy as np
    from paraview import simple
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOImage import vtkPNGReader
    simple.LoadPlugin(plugin, remote=False, ns=vars(simple))
    view = simple.CreateRenderView()
    view.ViewSize = SIZE
    view.OrientationAxesVisibility = 0
    view.Background = [0, 0, 0]
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    view.UseFXAA = 0
    # File > Open picks the reader by extension; a path that is no file is given to it directly.
    reader = simple.OpenDataFile(path) if os.path.isfile(path) else simple.MultiresolutionReservoir(FileName=path)
    result = {"reader": reader.GetXMLName()}
    reader.UpdatePipeline()
    display = simple.Show(reader, view)
    display.Representation = "Multiresolution Surface"
    data = reader.GetDataInformation().GetCellDataInformation()
    result["arrays"] = [data.GetArrayInformation(i).GetName() for i in range(data.GetNumberOfArrays())]
    display.WaitForDetailMs = 20000
    display.GridLines = 0
    # The solid colour: magenta, unlit (ambient only), both colours set as the GUI's Solid
    # Color does (lit as stock surfaces, the ambient term takes AmbientColor).
    display.DiffuseColor = display.AmbientColor = [1.0, 0.0, 1.0]
    display.Ambient = 1.0
    display.Diffuse = 0.0
    display.Specular = 0.0
    if property_name in result["arrays"]:
        simple.ColorBy(display, ("CELLS", property_name))
    view.ResetCamera(False)
    camera = view.GetActiveCamera()
    camera.Elevation(35)
    camera.Azimuth(20)
    if cut == "cut":
        display.PixelTolerance = 64  # the roots alone
        simple.Render(view)
        os.truncate(path, os.path.getsize(path) // 2)
    display.PixelTolerance = 0
    simple.Render(view)
    simple.Render(view)  # a second frame: the same error must not be reported again
    simple.SaveScreenshot(image, view, ImageResolution=SIZE, TransparentBackground=0)
    png = vtkPNGReader()
    png.SetFileName(image)
    png.Update()
    pixels = vtk_to_numpy(png.GetOutput().GetPointData().GetScalars())[:, :3].astype(int)
    covered = np.any(pixels > 8, axis=1)
    solid = (pixels[:, 0] > 200) & (pixels[:, 1] < 40) & (pixels[:, 2] > 200)
    display.UpdatePropertyInformation()
    reader.UpdatePropertyInformation()
    result.update(reader_error=reader.GetPropertyValue("LastError"),
                  display_error=display.GetPropertyValue("LastError"),
                  triangles=int(display.GetPropertyValue("TrianglesDrawn")),
                  covered=int(covered.sum()), solid=int(solid.sum()))
    print("RESULT " + json.dumps(result), flush=True)
    simple.Delete(display)
    simple.Delete(reader)
    simple.Delete(view)


if CHILD:
    i = sys.argv.index("--child")
    child(*sys.argv[i + 1:i + 6])
    raise SystemExit(0)

import resmr_testing as rt  # noqa: E402

args = rt.arguments()
resmr = os.environ["RESMR_EXECUTABLE"]
pvpython = os.environ["PVPYTHON_EXECUTABLE"]
temp = os.path.join(args.temp, "badinput")
shutil.rmtree(temp, ignore_errors=True)
os.makedirs(temp)


def run(*command):
    subprocess.run([resmr, *command], capture_output=True, text=True, check=True)


grid = os.path.join(temp, "model.EGRID")
good = os.path.join(temp, "good.resmr")
NZ = 8
run("synth", "60", "50", str(NZ), "-o", grid, "--quiet")
run("build", grid, "-o", good, "--quiet")
run("add-properties", good, grid)
with open(good, "rb") as source:
    data = source.read()
with open(good[:-6] + ".resmrp", "rb") as source:
    property_data = source.read()


def index_of(blob):
    """(offset, size) of the index of a .resmr or .resmrp, from its 32-byte trailer."""
    return struct.unpack_from("<QQ", blob, len(blob) - 32)


# The .resmr index: one 192-byte record a region (level, index, ..., at byte 104 the mesh
# chunk's offset and stored size), as many as the header's region count (at byte 128), then
# one 32-byte record a model chunk (kind, part, offset, stored size).
index_offset, index_size = index_of(data)
regions = []
region_count = struct.unpack_from("<Q", data, 128)[0]
position = index_offset
for _ in range(region_count):
    level, _, number = struct.unpack_from("<iiq", data, position)
    chunk, stored = struct.unpack_from("<QI", data, position + 104)
    regions.append((level, number, chunk, stored))
    position += 192
model = [struct.unpack_from("<IIQI", data, p) for p in range(position, index_offset + index_size, 32)]
hash_offsets = [m for m in model if m[0] == 2]
walls = [m for m in model if m[0] == 5]
leaf = max(regions, key=lambda r: (r[0], r[3]))
root = max((r for r in regions if r[0] == 0), key=lambda r: r[3])
# The .resmrp index: per table a 32-byte name, step, report number, days, minimum, maximum,
# then the packed chunk's reference (offset, stored, raw, CRC), the block ranges' and the layer
# blocks', and one a layer (one band a layer at this size).
p_offset, p_size = index_of(property_data)
poro = None
for position in range(p_offset, p_offset + p_size, 56 + 20 * (3 + NZ)):
    if property_data[position:position + 32].split(b"\0")[0] == b"PORO":
        poro = struct.unpack_from("<QI", property_data, position + 56)
if len(regions) < 4 or len(hash_offsets) != 1 or len(walls) != 1 or poro is None:
    rt.fail(f"could not read the indexes: {len(regions)} regions, {len(hash_offsets)} hash offset chunks, "
            f"{len(walls)} wall depth chunks, PORO {poro}")
print(f"{good}: {len(data)} bytes, {len(regions)} regions, {len(model)} model chunks; leaf damaged: level "
      f"{leaf[0]} index {leaf[1]}, root: index {root[1]}")


def with_field(blob, position, fmt, value, header_bytes):
    """`blob` with a header field set and the header CRC (CRC-32, at its end) recomputed."""
    out = bytearray(blob)
    struct.pack_into(fmt, out, position, value)
    struct.pack_into("<I", out, header_bytes - 4, zlib.crc32(bytes(out[:header_bytes - 4])))
    return bytes(out)


def flipped(blob, position):
    out = bytearray(blob)
    out[position] ^= 0x5A
    return bytes(out)


def write(name, blob, properties=None):
    """name.resmr (and name.resmrp) in the temporary folder; returns the .resmr path."""
    path = os.path.join(temp, name + ".resmr")
    with open(path, "wb") as out:
        out.write(blob)
    if properties is not None:
        with open(path[:-6] + ".resmrp", "wb") as out:
            out.write(properties)
    return path


rng = random.Random(7)
garbage = bytes(rng.randrange(256) for _ in range(256))
header = bytearray(data)
header[24:40] = bytes(16 * [0xFF])
folder = os.path.join(temp, "folder.resmr")
os.makedirs(folder)
P = property_data
# (name, .resmr path, file named by the error, fragments of the error, where: "reader" or
# "display", what is drawn: "nothing", "solid", "property", "less", "roots")
cases = [
    ("truncated", write("truncated", data[:(256 + index_offset) // 2], P), None,
     ["no index trailer", "truncated"], "reader", "nothing"),
    ("garbage header", write("garbage", garbage + data[256:], P), None, ["bad magic at byte 0"], "reader", "nothing"),
    ("damaged header", write("header", bytes(header), P), None, ["header checksum mismatch"], "reader", "nothing"),
    ("damaged index", write("index", flipped(data, index_offset + 192 * 2 + 60), P), None, ["index"], "reader", "nothing"),
    ("empty", write("empty", b""), None, ["0 bytes", "too short"], "reader", "nothing"),
    ("missing file", os.path.join(temp, "missing.resmr"), None, ["cannot open"], "reader", "nothing"),
    ("folder", folder, None, ["not a regular file"], "reader", "nothing"),
    ("truncated .resmrp", write("cutproperties", data, P[:len(P) // 2]), ".resmrp", ["no index trailer"], "reader",
     "nothing"),
    ("empty .resmrp", write("emptyproperties", data, b""), ".resmrp", ["0 bytes", "too short"], "reader", "nothing"),
    ("missing .resmrp", write("noproperties", data), None, [], None, "solid"),
    ("damaged region chunk", write("region", flipped(data, leaf[2] + leaf[3] // 2), P), None,
     [f"region (level {leaf[0]}, index {leaf[1]}) mesh at byte {leaf[2]}", "checksum mismatch"], "display", "property"),
    ("damaged root chunk", write("root", flipped(data, root[2] + root[3] // 2), P), None,
     [f"region (level 0, index {root[1]}) mesh at byte {root[2]}", "checksum mismatch"], "display", "less"),
    ("damaged hash chunk", write("hash", flipped(data, hash_offsets[0][2] + hash_offsets[0][3] // 2), P), None,
     ["hash offset table", f"at byte {hash_offsets[0][2]}", "checksum mismatch"], "display", "solid"),
    ("damaged wall depth table", write("walls", flipped(data, walls[0][2] + walls[0][3] // 2), P), None, [], None,
     "property"),
    ("damaged property table", write("poro", data, flipped(P, poro[0] + poro[1] // 2)), ".resmrp",
     ["PORO", f"at byte {poro[0]}", "checksum mismatch"], "display", "solid"),
    ("cut while open", write("cut", data, P), None, ["cut or rewritten in place"], "display", "roots"),
    ("flat lattice", write("flat", with_field(data, 112, "<d", 0.0, 256), P), None,
     ["header field 'lattice step (depth)' is 0"], "reader", "nothing"),
    ("0 tables .resmrp", write("notables", data, with_field(P, 56, "<I", 0, 128)), ".resmrp",
     ["header field 'table count' is 0"], "reader", "nothing"),
]


def render(path, cut=False):
    """The child's result, its VTK error lines and its output; None with the reason if it
    crashed or hung."""
    image = os.path.join(temp, os.path.basename(path)[:-6] + ".png")
    command = [pvpython, "--force-offscreen-rendering", os.path.abspath(__file__), "--child", args.plugin, path,
               "PORO", image, "cut" if cut else "-"]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        return None, f"no result within {TIMEOUT_S} s (a hang)"
    output = done.stdout + done.stderr
    lines = [line for line in done.stdout.splitlines() if line.startswith("RESULT ")]
    if done.returncode != 0 or not lines:
        return None, f"exit status {done.returncode} and no result (a crash): {output[-2000:]}"
    result = json.loads(lines[-1][len("RESULT "):])
    result["vtk_errors"] = [line for line in output.splitlines() if "ERR|" in line]
    return result, output


failures = []
reference, output = render(good)
if reference is None or reference["reader_error"] or reference["display_error"] or reference["triangles"] == 0:
    rt.fail(f"the good file does not draw cleanly: {reference or output}")
good_covered = reference["covered"]
print(f"good file: {reference['triangles']} triangles, {good_covered} pixels covered, {reference['solid']} solid")
if reference["solid"] > 0.01 * good_covered or good_covered < 0.1 * SIZE[0] * SIZE[1]:
    rt.fail(f"good file: {good_covered} pixels covered, {reference['solid']} in the solid colour: not coloured by PORO")

for name, path, named, fragments, where, drawn in cases:
    result, output = render(path, cut=name == "cut while open")
    if result is None:
        failures.append(f"{name}: {output}")
        print(f"{name}: {output}")
        continue
    shown = {k: v for k, v in result.items() if k != "vtk_errors"}
    print(f"{name}: {json.dumps(shown)}")
    for line in result["vtk_errors"][:3]:
        print(f"    VTK: {line.strip()[:300]}")
    problems = []
    file_named = path[:-6] + named if named else path
    if where is None:
        if result["reader_error"] or result["display_error"] or result["vtk_errors"]:
            problems.append("an error where none was expected")
    else:
        message = result["reader_error" if where == "reader" else "display_error"]
        missing = [f for f in [file_named] + fragments if f not in message]
        if missing:
            problems.append(f"the {where}'s LastError {message!r} lacks {missing}")
        reported = [line for line in result["vtk_errors"] if file_named in line and fragments[-1] in line]
        # The reader's error shows once a pipeline request (information, data) that failed;
        # the representation's once.
        if not reported or (where == "display" and len(reported) != 1):
            problems.append(f"VTK's error output names it {len(reported)} times: {result['vtk_errors'][:4]}")
    triangles, covered, solid = result["triangles"], result["covered"], result["solid"]
    if drawn == "nothing" and (triangles != 0 or covered != 0):
        problems.append(f"drew {triangles} triangles, {covered} pixels")
    if drawn == "solid" and not (covered > 0.9 * good_covered and solid > 0.95 * covered):
        problems.append(f"not the whole model in the solid colour: {covered} pixels ({solid} solid), "
                        f"the good file {good_covered}")
    if drawn == "property" and not (covered > 0.97 * good_covered and solid < 0.01 * covered):
        problems.append(f"not the whole model coloured by PORO: {covered} pixels ({solid} solid), "
                        f"the good file {good_covered}")
    if drawn in ("less", "roots") and not (0 < covered and triangles > 0):
        problems.append(f"drew nothing ({triangles} triangles, {covered} pixels)")
    if name == "damaged wall depth table" and not any(
            "WARN|" in line and path in line and "wall depth table" in line for line in output.splitlines()):
        problems.append("no warning naming the file and the wall depth table")
    if name == "missing .resmrp" and result["arrays"]:
        problems.append(f"properties listed without a property file: {result['arrays']}")
    failures.extend(f"{name}: {p}" for p in problems)

if failures:
    rt.fail("\n".join(failures))
print(f"{len(cases)} damaged inputs: clear errors naming the file, no crash, no hang")
