# Included before find_package(ParaView). Debian 13's paraview-dev exports the targets of
# VTK's and ParaView's Python modules with the file NAME.so, while python3-paraview installs
# NAME.cpython-313-x86_64-linux-gnu.so, so CMake's generated import check stops
# find_package(ParaView) although this project links none of those targets. Since CMake 3.28
# that check skips a target whose _cmake_import_check_xcframework_for_<target> names an
# existing directory (meant for Apple xcframeworks). Just as each targets file starts its
# check, this sets that variable for exactly the targets whose file is missing but present
# under an ABI-tagged name; any other missing file still stops configure. Nothing to do
# before 3.28: Debian 12's CMake 3.25 comes with ParaView 5.11, which has no such fault.
if (CMAKE_VERSION VERSION_LESS "3.28")
  return ()
endif ()

# A macro, so that its set() reaches the scope in which the check runs. It reads the target
# list from its argument: reading the watched variable itself would call it again.
macro (_resmr_skip_misnamed_python_modules variable access value list_file)
  # The check reads the list in the main <export>-targets.cmake, after every
  # <export>-targets-<config>.cmake has added its targets and files.
  if ("${access}" STREQUAL "READ_ACCESS" AND "${list_file}" MATCHES "-targets\\.cmake$")
    foreach (_resmr_target IN ITEMS ${value})
      foreach (_resmr_file IN LISTS "_cmake_import_check_files_for_${_resmr_target}")
        if (NOT EXISTS "${_resmr_file}" AND _resmr_file MATCHES "^(.+)\\.so$")
          file(GLOB _resmr_tagged "${CMAKE_MATCH_1}.cpython-*.so")
          if (_resmr_tagged)
            set("_cmake_import_check_xcframework_for_${_resmr_target}" "${CMAKE_BINARY_DIR}")
          endif ()
        endif ()
      endforeach ()
    endforeach ()
    unset(_resmr_target)
    unset(_resmr_file)
    unset(_resmr_tagged)
  endif ()
endmacro ()
variable_watch(_cmake_import_check_targets _resmr_skip_misnamed_python_modules)
