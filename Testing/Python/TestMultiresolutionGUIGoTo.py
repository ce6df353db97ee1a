"""Go to a cell and to a map point from the Multiresolution Readout dock, in the ParaView GUI.

`paraview` opens a generated faulted model seen from above (a startup script that waits for
every mesh at 0 px), then plays a QtTesting script (ParaView's own test playback, widgets named
by their object names) that types I, J, K of one top cell into the dock's 'Go to cell' boxes
and presses the button, then the map x, y and depth of the middle of another top cell's top
face into 'Go to point' and presses that one. The GUI's TRACE log must show each cell selected
(outlined, its text kept in the dock): the first by its I, J, K, the second as the cell the
view's centre then shows. The cells and their corners come from pvpython (resmr_inspect) on the
same file. Skipped without a paraview executable or an X display."""
import os
import re
import subprocess
import time

import resmr_testing as rt

args = rt.arguments()
paraview, temp, path = rt.gui_model(args, "gui-goto")

# Two active top cells and the middle of the second's top face, from pvpython.
from paraview import simple  # noqa: E402

rt.load_plugin(args.plugin)
import resmr_inspect  # noqa: E402

view = simple.CreateRenderView()
reader = simple.OpenDataFile(path)
display = simple.Show(reader, view)
simple.Render(view)
chosen = []
for i, j in ((60, 50), (62, 55), (58, 45), (40, 40), (80, 60), (30, 70), (90, 30)):
    cell = resmr_inspect.InspectCell(i, j, 1, view, display)
    if cell is not None and cell["active"]:
        chosen.append(cell)
    if len(chosen) == 2:
        break
if len(chosen) < 2:
    rt.fail(f"fewer than two active top cells among those tried: {chosen}")
first, second = chosen
top = [sum(c[a] for c in second["corners"][:4]) / 4 for a in range(3)]
simple.Delete(display)
simple.Delete(reader)
simple.Delete(view)
print(f"go to cell ({first['I']}, {first['J']}, {first['K']}); go to point ({top[0]:.2f}, {top[1]:.2f}, depth "
      f"{-top[2]:.2f}), the top of ({second['I']}, {second['J']}, {second['K']})")

setup = os.path.join(temp, "setup.py")
with open(setup, "w") as script:
    script.write(f"""import logging
logging.raiseExceptions = False  # see TestMultiresolutionGUI.py
from paraview.simple import *
reader = OpenDataFile({path!r})
display = Show(reader)
ColorBy(display, ("CELLS", "PORO"))
display.PixelTolerance = 0
display.WaitForDetailMs = 600000  # every frame complete: the pick after a go-to sees the finest cells
view = GetActiveView()
view.CameraPosition = [0, 0, 1]
view.CameraFocalPoint = [0, 0, 0]
view.CameraViewUp = [0, 1, 0]
view.ResetCamera(False)
Render()
""")
dock = "pqClientMainWindow/pqMultiresolutionReadoutDock/ReadoutBody"
events = [(f"{dock}/GoToCellRow/GoTo{axis}", "set_int", str(first[axis])) for axis in "IJK"]
events.append((f"{dock}/GoToCellRow/GoToCell", "activate", ""))
events += [(f"{dock}/GoToPointRow/GoTo{axis}", "set_double", f"{value:.4f}")
           for axis, value in (("X", top[0]), ("Y", top[1]), ("Depth", -top[2]))]
events.append((f"{dock}/GoToPointRow/GoToPoint", "activate", ""))
playback = os.path.join(temp, "goto.xml")
with open(playback, "w") as xml:
    xml.write('<?xml version="1.0" ?>\n<pqevents>\n')
    for name, command, argument in events:
        xml.write(f'  <pqevent object="{name}" command="{command}" arguments="{argument}" />\n')
    xml.write("</pqevents>\n")

trace = os.path.join(temp, "trace.log")
if os.path.exists(trace):
    os.remove(trace)
environment = dict(os.environ, PV_PLUGIN_PATH=os.path.dirname(args.plugin))
start = time.time()
gui = subprocess.run([paraview, "--dr", f"--script={setup}", f"--test-script={playback}", "--exit",
                      f"--log={trace},TRACE"], env=environment, capture_output=True, text=True, timeout=300)
print(f"paraview played {len(events)} events and exited ({gui.returncode}) in {time.time() - start:.1f} s")

SELECTED = re.compile(r"multiresolution selected: Cell I (\d+), J (\d+), K (\d+)")
WENT = re.compile(r"multiresolution go to point \(([-\d.e+]+), ([-\d.e+]+), depth ([-\d.e+]+)\)")
with open(trace, errors="replace") as log:
    lines = log.readlines()
selected = [tuple(int(v) for v in m.group(1, 2, 3)) for m in (SELECTED.search(line) for line in lines) if m]
went = [m for m in (WENT.search(line) for line in lines) if m]
print(f"selected: {selected}; go to point logged: {[m.group(0) for m in went]}")
failures = []
if gui.returncode != 0:
    failures.append(f"paraview exited with {gui.returncode}: {gui.stdout[-2000:]} {gui.stderr[-2000:]}")
expected = [(first["I"], first["J"], first["K"]), (second["I"], second["J"], second["K"])]
if selected != expected:
    failures.append(f"the dock selected {selected}, not {expected} (go to cell, then go to point)")
if len(went) != 1 or abs(float(went[0].group(1)) - top[0]) > 0.01 or abs(float(went[0].group(3)) + top[2]) > 0.01:
    failures.append("the go to point request did not reach the dock with the point typed")
if failures:
    rt.fail("; ".join(failures))
print("the dock went to the cell and to the point, and selected each")
