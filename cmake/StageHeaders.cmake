# Copies fleetmap's public headers into <OUTPUT_DIR>/fleetmap/<module>/..., turning their includes
# of each other ("core/transform2.h") into the installed spelling ("fleetmap/core/transform2.h"),
# so that an installed tree needs only <prefix>/include on the include path and no header of it can
# be shadowed by another package's "core/..." or "io/...".
# Fails (naming each header and what it uses) when a public header includes OpenCV, yaml-cpp or
# nlohmann-json, or names their types (cv::, YAML::, nlohmann::) outside comments: installed headers
# speak fleetmap's own types; a header that needs those goes to FLEETMAP_INTERNAL_HEADERS.
# cmake -DSOURCE_DIR=<repo> -DOUTPUT_DIR=<dir> -DLIST_FILE=<file: one header a line> -DMODULES=<a|b|c>
#       -DSTAMP=<file> -P StageHeaders.cmake
cmake_minimum_required(VERSION 3.22)
file(STRINGS "${LIST_FILE}" headers)
file(REMOVE_RECURSE "${OUTPUT_DIR}/fleetmap")
set(pattern "#include \"((${MODULES})/[^\"]+)\"")
set(third_party_include "#[ \t]*include[ \t]*[<\"](opencv2?|yaml-cpp|nlohmann)[/.][^>\"]*[>\"]")
set(third_party_type "(^|[^A-Za-z0-9_])(cv|YAML|nlohmann)::[A-Za-z_][A-Za-z0-9_]*")
set(third_party_uses "")
foreach(header IN LISTS headers)
  file(READ "${SOURCE_DIR}/${header}" text)
  string(REGEX REPLACE "//[^\n]*" "" code "${text}")
  string(REGEX REPLACE "/\\*([^*]|\\*+[^*/])*\\*+/" "" code "${code}")
  string(REGEX MATCHALL "${third_party_include}" found "${code}")
  string(REGEX MATCHALL "${third_party_type}" types "${code}")
  foreach(type IN LISTS types)
    string(REGEX REPLACE "${third_party_type}" "\\2::" type "${type}")
    list(APPEND found "${type}")
  endforeach()
  if(found)
    list(REMOVE_DUPLICATES found)
    list(JOIN found ", " found)
    string(APPEND third_party_uses "\n  ${header}: ${found}")
  endif()
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
if(third_party_uses)
  message(FATAL_ERROR "public headers use third-party types (keep them internal: FLEETMAP_INTERNAL_HEADERS in "
                      "cmake/FleetmapInstall.cmake):${third_party_uses}")
endif()
file(TOUCH "${STAMP}")
