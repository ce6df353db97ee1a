# The plugin's tests: pvpython, pvbatch under MPI, pvserver and the GUI (included from
# CMakeLists.txt when the plugin is built).
set(plugin_file "$<TARGET_FILE:ReservoirMultiresolution>")
find_program(PVPYTHON_EXECUTABLE pvpython REQUIRED)

# Two MPI ranks (mpirun -np 2 pvbatch --symmetric) build the file one process builds. Judged
# by mpirun's exit status (non-zero when a rank fails), with no pass pattern to override it.
find_program(MPIEXEC_EXECUTABLE NAMES mpirun mpiexec)
find_program(PVBATCH_EXECUTABLE pvbatch REQUIRED)
add_test(NAME Multiresolution.MPIBuild
  COMMAND "${MPIEXEC_EXECUTABLE}" --allow-run-as-root --oversubscribe -np 2
          "${PVBATCH_EXECUTABLE}" --symmetric --force-offscreen-rendering
          "${CMAKE_CURRENT_SOURCE_DIR}/Python/TestBuildHierarchyMPI.py"
          --plugin "${plugin_file}" --temp "${CMAKE_CURRENT_BINARY_DIR}/Temporary/mpi"
          --resmr "$<TARGET_FILE:resmr>")
set_tests_properties(Multiresolution.MPIBuild PROPERTIES
  ENVIRONMENT "PYTHONPATH=${CMAKE_CURRENT_SOURCE_DIR}/Python;OMPI_MCA_rmaps_base_oversubscribe=1"
  FAIL_REGULAR_EXPRESSION "FAIL;Traceback"
  TIMEOUT 600)
# The same at the scale a cluster is asked for: two ranks on 100M cells (Cmax chosen from the
# model, one worker a rank, a shared scratch folder) write a whole file: every level and
# region once, the finest level holding the model's 57,083,593 active cells (the synthetic
# generator's count for seed 1, as the build report gives it), a coarse level read back. About
# 15 minutes on 2 cores. Its equality with the one-process file is the small test's above; at
# this size the one-process build would double the time (`--reference one-process`, see the
# build benchmarks).
add_test(NAME Multiresolution.MPIBuild100M
  COMMAND "${MPIEXEC_EXECUTABLE}" --allow-run-as-root --oversubscribe -np 2
          "${PVBATCH_EXECUTABLE}" --symmetric --force-offscreen-rendering
          "${CMAKE_CURRENT_SOURCE_DIR}/Python/TestBuildHierarchyMPI.py"
          --plugin "${plugin_file}" --temp "${CMAKE_CURRENT_BINARY_DIR}/Temporary/mpi100m"
          --resmr "$<TARGET_FILE:resmr>" --model synth:1000x1000x100:1 --cmax 0 --threads 1
          --reference none --active 57083593)
set_tests_properties(Multiresolution.MPIBuild100M PROPERTIES
  ENVIRONMENT "PYTHONPATH=${CMAKE_CURRENT_SOURCE_DIR}/Python;OMPI_MCA_rmaps_base_oversubscribe=1"
  FAIL_REGULAR_EXPRESSION "FAIL;Traceback"
  TIMEOUT 2400 LABELS "scale")

# pvpython tests through the plugin's GRDECLReader proxy.
function (resmr_add_pvpython_test name script)
  add_test(NAME ${name}
    COMMAND "${PVPYTHON_EXECUTABLE}" --force-offscreen-rendering
            "${CMAKE_CURRENT_SOURCE_DIR}/Python/${script}"
            --plugin "${plugin_file}" --data "${RESMR_DATA_DIR}"
            --baselines "${CMAKE_CURRENT_SOURCE_DIR}/Data/Baseline"
            --temp "${CMAKE_CURRENT_BINARY_DIR}/Temporary")
  # A GL error skips draws without a word in the image tests: VTK's report of one fails them.
  set_tests_properties(${name} PROPERTIES
    ENVIRONMENT "PYTHONPATH=${CMAKE_CURRENT_SOURCE_DIR}/Python"
    FAIL_REGULAR_EXPRESSION "FAIL;Traceback;OpenGL errors detected"
    TIMEOUT 600)
endfunction ()
resmr_add_pvpython_test(Reader.CornersAgainstOPM TestCornersAgainstOPM.py)
resmr_add_pvpython_test(Reader.BadInput TestReaderBadInput.py)
resmr_add_pvpython_test(Reader.Images TestReaderImages.py)
# Edit and skipped keywords of every class inserted into Reek's and SPE9's decks: equal to
# OPM's EclipseState, one warning each, resmr info and build open them.
resmr_add_pvpython_test(Reader.DeckEditsAgainstOPM TestDeckEditsAgainstOPM.py)
set_property(TEST Reader.DeckEditsAgainstOPM APPEND PROPERTY
  ENVIRONMENT "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>")
resmr_add_pvpython_test(EGRIDReader.AgainstOPM TestEGRIDAgainstOPM.py)
# The same with every record of 1000+ values read by several threads.
resmr_add_pvpython_test(EGRIDReader.AgainstOPMParallelReads TestEGRIDAgainstOPM.py)
set_property(TEST EGRIDReader.AgainstOPMParallelReads APPEND PROPERTY
  ENVIRONMENT "RESMR_PARALLEL_MIN_VALUES=1000")
resmr_add_pvpython_test(EGRIDReader.Images TestEGRIDReaderImages.py)
resmr_add_pvpython_test(EGRIDReader.StepMemory TestEGRIDStepMemory.py)
resmr_add_pvpython_test(EGRIDReader.BadInput TestEGRIDReaderBadInput.py)
# A run still being written: ReloadFiles offers each step as it completes (EGRIDReader, and
# the .resmrp resmr add-properties extends, through the Multiresolution Surface).
resmr_add_pvpython_test(EGRIDReader.RunBeingWritten TestRunBeingWritten.py)
set_property(TEST EGRIDReader.RunBeingWritten APPEND PROPERTY ENVIRONMENT "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>")

# Generated models: resmr synth's files in our reader, OPM and (when given a Python with
# resdata from PyPI) resdata; the SyntheticReservoir source; memory refusals; images.
set(RESMR_RESDATA_PYTHON "" CACHE FILEPATH
  "A Python with resdata (PyPI) to cross-check generated EGRIDs; empty: not checked")
resmr_add_pvpython_test(Synthetic.EndToEnd TestSyntheticReservoir.py)
set_property(TEST Synthetic.EndToEnd APPEND PROPERTY ENVIRONMENT
  "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>" "RESMR_RESDATA_PYTHON=${RESMR_RESDATA_PYTHON}")

resmr_add_pvpython_test(Simplify.Reek TestSimplifyReservoirGrid.py)

resmr_add_pvpython_test(Multiresolution.ExtractLevel TestExtractMultiresolutionLevel.py)
set_property(TEST Multiresolution.ExtractLevel APPEND PROPERTY ENVIRONMENT "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>")

resmr_add_pvpython_test(Multiresolution.Reader TestMultiresolutionReader.py)
set_property(TEST Multiresolution.Reader APPEND PROPERTY ENVIRONMENT "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>")
# The Multiresolution Surface against stock ParaView, pixel by pixel (cell ids, cracks, colours).
resmr_add_pvpython_test(Multiresolution.Surface TestMultiresolutionSurface.py)
set_property(TEST Multiresolution.Surface APPEND PROPERTY ENVIRONMENT "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>")
# Its single-layer mode (Layer = K) against stock ParaView's layer K (Threshold), pixel by pixel.
resmr_add_pvpython_test(Multiresolution.Layer TestMultiresolutionLayer.py)
set_property(TEST Multiresolution.Layer APPEND PROPERTY ENVIRONMENT "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>")
# Every level and random cuts: no see-through hole, no pixel in the NaN colour.
resmr_add_pvpython_test(Multiresolution.EveryLevel TestMultiresolutionEveryLevel.py)
set_property(TEST Multiresolution.EveryLevel APPEND PROPERTY ENVIRONMENT "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>")
# Walls show their layers where they are at every level (the wall depth table), and do worse
# with it damaged.
resmr_add_pvpython_test(Multiresolution.WallLayers TestMultiresolutionWallLayers.py)
set_property(TEST Multiresolution.WallLayers APPEND PROPERTY ENVIRONMENT "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>")
# Lit as stock ParaView lights its surfaces: light kit, headlight and material (PSNR).
resmr_add_pvpython_test(Multiresolution.Lighting TestMultiresolutionLighting.py)
set_property(TEST Multiresolution.Lighting APPEND PROPERTY ENVIRONMENT "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>")
# The quality floor under slow frames, still frames at the user's tolerance, and moving frames
# drawn again from their tolerance.
resmr_add_pvpython_test(Multiresolution.QualityFloor TestMultiresolutionQualityFloor.py)
set_property(TEST Multiresolution.QualityFloor APPEND PROPERTY ENVIRONMENT "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>")
# Moving frames at a reduced resolution, stretched onto the view with their depth; the still
# frame in full.
resmr_add_pvpython_test(Multiresolution.MovingResolution TestMultiresolutionMovingResolution.py)
set_property(TEST Multiresolution.MovingResolution APPEND PROPERTY ENVIRONMENT "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>")
# Resident memory within the budget over 1,000 frames of an orbit, zoom and low flight on a
# 10M-cell synthetic model (built once, about 4 minutes on 2 cores, then reused from
# Temporary/budget); no leak, no error.
resmr_add_pvpython_test(Multiresolution.Budget TestMultiresolutionBudget.py)
set_property(TEST Multiresolution.Budget APPEND PROPERTY ENVIRONMENT "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>")
set_tests_properties(Multiresolution.Budget PROPERTIES TIMEOUT 1800)
# Damaged .resmr/.resmrp files (truncated, garbage or damaged header, index, region, hash and
# property chunks, empty, missing, cut while open) through the reader and the representation,
# one pvpython process each: a clear error naming the file, no crash, no hang.
resmr_add_pvpython_test(Multiresolution.BadInput TestMultiresolutionBadInput.py)
set_property(TEST Multiresolution.BadInput APPEND PROPERTY ENVIRONMENT
  "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>" "PVPYTHON_EXECUTABLE=${PVPYTHON_EXECUTABLE}")
# The same through pvserver (plugin on both sides): the server renders, the client gets the image.
find_program(PVSERVER_EXECUTABLE pvserver REQUIRED)
resmr_add_pvpython_test(Multiresolution.ClientServer TestMultiresolutionClientServer.py)
set_property(TEST Multiresolution.ClientServer APPEND PROPERTY ENVIRONMENT
  "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>" "PVSERVER_EXECUTABLE=${PVSERVER_EXECUTABLE}")
# The GUI: progressive refresh while meshes load and the readout dock (skipped without paraview).
find_program(PARAVIEW_EXECUTABLE paraview)
resmr_add_pvpython_test(Multiresolution.GUI TestMultiresolutionGUI.py)
set_property(TEST Multiresolution.GUI APPEND PROPERTY ENVIRONMENT
  "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>" "PARAVIEW_EXECUTABLE=${PARAVIEW_EXECUTABLE}")
set_property(TEST Multiresolution.GUI PROPERTY SKIP_RETURN_CODE 125)
# The dock's Go to cell and Go to point, played by ParaView's test playback (skipped without paraview).
resmr_add_pvpython_test(Multiresolution.GUIGoTo TestMultiresolutionGUIGoTo.py)
set_property(TEST Multiresolution.GUIGoTo APPEND PROPERTY ENVIRONMENT
  "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>" "PARAVIEW_EXECUTABLE=${PARAVIEW_EXECUTABLE}")
set_property(TEST Multiresolution.GUIGoTo PROPERTY SKIP_RETURN_CODE 125)
# Multiresolution Extract Subset and Threshold set through the Properties panel, by ParaView's test playback.
resmr_add_pvpython_test(Multiresolution.GUIFilters TestMultiresolutionGUIFilters.py)
set_property(TEST Multiresolution.GUIFilters APPEND PROPERTY ENVIRONMENT
  "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>" "PARAVIEW_EXECUTABLE=${PARAVIEW_EXECUTABLE}")
set_property(TEST Multiresolution.GUIFilters PROPERTY SKIP_RETURN_CODE 125)

# Picking a cell: the frame's own cell at any level, stock's at 0 px, EGRIDReader's values and corners.
resmr_add_pvpython_test(Multiresolution.Pick TestMultiresolutionPick.py)
set_property(TEST Multiresolution.Pick APPEND PROPERTY ENVIRONMENT "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>")
# The I/J/K range filter (Multiresolution Extract Subset) against stock ParaView's Threshold
# on I, J, K and ACTNUM of the full grid, pixel by pixel; coarse tolerances stay in range.
resmr_add_pvpython_test(Multiresolution.Range TestMultiresolutionRange.py)
set_property(TEST Multiresolution.Range APPEND PROPERTY ENVIRONMENT "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>")
resmr_add_pvpython_test(Multiresolution.Threshold TestMultiresolutionThreshold.py)
set_property(TEST Multiresolution.Threshold APPEND PROPERTY ENVIRONMENT "RESMR_EXECUTABLE=$<TARGET_FILE:resmr>")
