# Copies fleetmap's public headers into <OUTPUT_DIR>/fleetmap/<module>/..., turning their includes
# of each other ("core/transform2.h") into the installed spelling ("fleetmap/core/transform2.h"),
# so that an installed tree needs only <prefix>/include on the include path and no header of it can
# be shadowed by another package's "core/..." or "io/...".
# cmake -DSOURCE_DIR=<repo> -DOUTPUT_DIR=<dir> -DLIST_FILE=<file: one header a line> -DMODULES=<a|b|c>
#       -DSTAMP=<file> -P StageHeaders.cmake
cmake_minimum_required(VERSION 3.22)
file(STRINGS "${LIST_FILE}" headers)
file(REMOVE_RECURSE "${OUTPUT_DIR}/fleetmap")
set(pattern "#include \"((${MODULES})/[^\"]+)\"")
foreach(header IN LISTS headers)
  file(READ "${SOURCE_DIR}/${header}" text)
  # Every header of fleetmap that a public header includes must itself be public.
  string(REGEX MATCHALL "${pattern}" includes "${text}")
  foreach(line IN LISTS includes)
    string(REGEX REPLACE "${pattern}" "\\1" included "${line}")
    if(NOT included IN_LIST headers)
      message(FATAL_ERROR "${header}: includes ${included}, which is not installed (cmake/FleetmapInstall.cmake)")
    endif()
  endforeach()
  string(REGEX REPLACE "${pattern}" "#include \"fleetmap/\\1\"" text "${text}")
  file(WRITE "${OUTPUT_DIR}/fleetmap/${header}" "${text}")
endforeach()
file(TOUCH "${STAMP}")
