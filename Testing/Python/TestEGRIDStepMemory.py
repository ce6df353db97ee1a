"""Steps through all 90 SPE9 report steps twice and checks that memory does not grow with
the number of steps visited (only the step shown is held), and that each step is read from
its own records (SWAT differs between consecutive steps, the reported step follows)."""
import os
import resource

import numpy as np
from paraview import servermanager, simple

import resmr_testing as rt

args = rt.arguments()
rt.load_plugin(args.plugin)
path = os.path.join(args.data, "spe9/opmflow2022_run_of_opm-data_SPE9_CP/SPE9_CP.EGRID")


def resident_bytes():
    with open("/proc/self/statm") as handle:
        return int(handle.read().split()[1]) * resource.getpagesize()


reader = simple.EGRIDReader(FileName=path)
reader.UpdatePipelineInformation()
times = list(reader.TimestepValues)
if len(times) != 90:
    rt.fail(f"SPE9 has {len(times)} time steps, expected 90")
samples = []
previous = None
for sweep in range(3):
    for index, time in enumerate(times):
        reader.UpdatePipeline(time)
        grid = servermanager.Fetch(reader, arg1=None, arg2=None, idx=0)
        if grid.GetFieldData().GetArray("ReportStep").GetValue(0) != index + 1:
            rt.fail(f"time {time}: report {grid.GetFieldData().GetArray('ReportStep').GetValue(0)}")
        swat = rt.cell_array(grid, "SWAT").copy()
        if previous is not None and index > 0 and np.array_equal(swat, previous):
            rt.fail(f"report {index + 1}: SWAT identical to the previous step")
        previous = swat
        del grid
        if sweep == 0 and index == 9:
            after_ten = resident_bytes()
            print(f"after the first 10 steps: resident {after_ten / 2**20:.1f} MiB")
    samples.append(resident_bytes())
    print(f"after sweep {sweep + 1} over {len(times)} steps: resident {samples[-1] / 2**20:.1f} MiB")
# One SPE9 step is 4 arrays x 9000 cells x 4 bytes = 144 KiB; holding every step visited
# would add 80 x 144 KiB = 11 MiB by the end of the first sweep and 25 MiB by the third
# (arrays fetched to this process are copies too). Allow 2 MiB of allocator noise.
growth = samples[2] - after_ten
print(f"growth from step 10 to the end of sweep 3 (260 more steps visited): {growth / 2**20:.2f} MiB")
if growth > 2 * 2**20:
    rt.fail(f"memory grew by {growth / 2**20:.2f} MiB while revisiting steps")
print("memory does not grow with the steps visited")
