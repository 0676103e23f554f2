# The staging step's check (cmake/StageHeaders.cmake) on made-up headers: it passes a header that
# names OpenCV only in comments, and fails, naming the header and what it uses, on headers that
# include OpenCV, yaml-cpp or nlohmann-json or use their types.
# cmake -DSTAGE_SCRIPT=<cmake/StageHeaders.cmake> -DWORK_DIR=<scratch> -P header_check_test.cmake
file(REMOVE_RECURSE ${WORK_DIR})
file(WRITE ${WORK_DIR}/src/merging/clean.h
     "#pragma once\n// Like cv::Mat, but ours; /* YAML::Node */ too.\n#include <vector>\n#include \"merging/other.h\"\n"
     "namespace fleetmap { struct Clean { std::vector<int> cells; }; }\n")
file(WRITE ${WORK_DIR}/src/merging/other.h "#pragma once\n")
file(WRITE ${WORK_DIR}/src/merging/opencv.h "#pragma once\n#include <opencv2/core/mat.hpp>\n")
file(WRITE ${WORK_DIR}/src/merging/types.h
     "#pragma once\nnamespace fleetmap { struct T { ::cv::Mat image; YAML::Node node; }; }\n")
file(WRITE ${WORK_DIR}/src/merging/json.h "#pragma once\n#include \"nlohmann/json.hpp\"\nnlohmann::json j;\n")

function(stage result_var output_var)
  list(JOIN ARGN "\n" list_text)
  file(WRITE ${WORK_DIR}/list.txt "${list_text}\n")
  execute_process(COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${WORK_DIR}/src -DOUTPUT_DIR=${WORK_DIR}/out
                          -DLIST_FILE=${WORK_DIR}/list.txt -DMODULES=merging -DSTAMP=${WORK_DIR}/stamp
                          -P ${STAGE_SCRIPT}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(${result_var} ${rc} PARENT_SCOPE)
  set(${output_var} "${out}${err}" PARENT_SCOPE)
endfunction()

stage(rc out merging/clean.h merging/other.h)
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK_DIR}/out/fleetmap/merging/clean.h)
  message(FATAL_ERROR "header check: a clean header was refused (${rc}):\n${out}")
endif()
file(READ ${WORK_DIR}/out/fleetmap/merging/clean.h staged)
if(NOT staged MATCHES "#include \"fleetmap/merging/other.h\"")
  message(FATAL_ERROR "header check: the staged header's include was not rewritten:\n${staged}")
endif()

stage(rc out merging/clean.h merging/other.h merging/opencv.h merging/types.h merging/json.h)
if(rc EQUAL 0)
  message(FATAL_ERROR "header check: headers with third-party types passed")
endif()
foreach(expected "merging/opencv.h: #include <opencv2/core/mat.hpp>" "merging/types.h: cv::, YAML::"
                 "merging/json.h: #include \"nlohmann/json.hpp\", nlohmann::")
  string(FIND "${out}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "header check: the message does not say \"${expected}\":\n${out}")
  endif()
endforeach()
string(FIND "${out}" "merging/clean.h" at)
if(NOT at EQUAL -1)
  message(FATAL_ERROR "header check: the clean header was named:\n${out}")
endif()
message(STATUS "header check: ok")
