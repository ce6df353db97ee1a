"""Multiresolution Extract Subset and Multiresolution Threshold set through ParaView's
Properties panel, in the GUI.

`paraview` opens a generated faulted model (a startup script), then plays a QtTesting script
(ParaView's own test playback, widgets named by their object names): Filters > Alphabetical >
Multiresolution Extract Subset, the six VOI boxes of the Properties panel typed, Apply; then
Filters > Alphabetical > Multiresolution Threshold on it, PORO picked in the Scalars list, the
lower and upper thresholds typed, Apply. The GUI's TRACE log must show the Multiresolution
Surface drawing the whole grid, then that range (its I, J, K from 1), then the range with the
PORO filter, with regions and triangles drawn after each. Skipped without a paraview
executable or an X display."""
import os
import re
import subprocess
import time

import resmr_testing as rt

args = rt.arguments()
paraview, temp, path = rt.gui_model(args, "gui-range")
voi = [31, 80, 21, 60, 4, 12]  # of the 120 x 100 x 16 model
poro = (0.15, 0.25)

setup = os.path.join(temp, "setup.py")
with open(setup, "w") as script:
    script.write(f"""import logging
logging.raiseExceptions = False  # see TestMultiresolutionGUI.py
from paraview.simple import *
reader = OpenDataFile({path!r})
display = Show(reader)
ColorBy(display, ("CELLS", "PORO"))
display.WaitForDetailMs = 600000
SetActiveSource(reader)
Render()
""")
panel = ("pqClientMainWindow/propertiesDock/propertiesPanel/scrollArea/qt_scrollarea_viewport/"
         "scrollAreaWidgetContents/PropertiesFrame/ProxyPanel")
events = [("pqClientMainWindow/menubar/menuFilters/Alphabetical", "activate", "MultiresolutionExtractSubset")]
events += [(f"{panel}/VOI/LineEdit{n}", "set_string", str(value)) for n, value in enumerate(voi)]
accept = ("pqClientMainWindow/propertiesDock/propertiesPanel/Accept", "activate", "")
events.append(accept)
events += [("pqClientMainWindow/menubar/menuFilters/Alphabetical", "activate", "MultiresolutionThreshold"),
           (f"{panel}/SelectInputScalars/ComboBox", "activated", "PORO"),
           (f"{panel}/LowerThreshold/DoubleRangeWidget/DoubleLineEdit", "set_string", str(poro[0])),
           (f"{panel}/UpperThreshold/DoubleRangeWidget/DoubleLineEdit", "set_string", str(poro[1])), accept]
playback = os.path.join(temp, "range.xml")
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

SHOWN = re.compile(r"multiresolution range shown: (.*) of ")
DRAWN = re.compile(r"multiresolution surface: (\d+) regions, (\d+) triangles")
with open(trace, errors="replace") as log:
    lines = log.readlines()
shown = [(n, m.group(1)) for n, m in ((n, SHOWN.search(line)) for n, line in enumerate(lines)) if m]
expected = f"I {voi[0]}-{voi[1]}, J {voi[2]}-{voi[3]}, K {voi[4]}-{voi[5]}"
filtered = f"{expected}, PORO {poro[0]:.6f} to {poro[1]:.6f}"
print(f"ranges shown: {[s for _, s in shown]}")
failures = []
if gui.returncode != 0:
    failures.append(f"paraview exited with {gui.returncode}: {gui.stdout[-2000:]} {gui.stderr[-2000:]}")
wanted = ["the whole grid", expected, filtered]
if [s for _, s in shown] != wanted:
    failures.append(f"the surface showed {[s for _, s in shown]}, not {wanted}")
else:
    for at, (start_line, text) in enumerate(shown):
        end_line = shown[at + 1][0] if at + 1 < len(shown) else len(lines)
        after = [DRAWN.search(line) for line in lines[start_line:end_line]]
        frames = [(int(m.group(1)), int(m.group(2))) for m in after if m]
        print(f"frames with {text}: {frames[:5]}{' ...' if len(frames) > 5 else ''}")
        if not frames or frames[-1][0] == 0 or frames[-1][1] == 0:
            failures.append(f"no region drawn with {text}: {frames}")
if failures:
    rt.fail("; ".join(failures))
print("the Properties panel set the range and the property filter, and the surface drew them")
