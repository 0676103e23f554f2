# Installs the build into a prefix under WORK_DIR, then configures, builds and runs the consumer
# project against it: what a program of its own goes through with find_package(fleetmap).
# cmake -DBUILD_DIR=<fleetmap build> -DWORK_DIR=<scratch> -DCONSUMER_DIR=<tests/install/consumer>
#       -DGENERATOR=<generator> -DCXX_COMPILER=<c++> [-DLAUNCHER=<ccache>]
#       [-DPYTHON=<python> -DPYTHON_DIR=<the package's folder under the prefix>] -P install_test.cmake
function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "install test: ${what} failed (${rc}):\n${out}\n${err}")
  endif()
  message(STATUS "${what}: ok\n${out}")
endfunction()

set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${prefix})  # the consumer's own build stays, so that ccache and ninja reuse it
run("cmake --install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
foreach(expected include/fleetmap/core/transform2.h include/fleetmap/sim/simulation.h include/fleetmap/sim/run_files.h
                 lib/cmake/fleetmap/fleetmapConfig.cmake)
  if(NOT EXISTS ${prefix}/${expected})
    message(FATAL_ERROR "install test: ${expected} is not installed")
  endif()
endforeach()
# No installed header may still include another one the build-tree way ("core/...").
file(GLOB_RECURSE headers ${prefix}/include/fleetmap/*.h)
foreach(header IN LISTS headers)
  file(STRINGS ${header} bad REGEX "#include \"(core|mapping|io|viz|maps|localization|merging|planning|exploration|sim|sweep|experiments)/")
  if(bad)
    message(FATAL_ERROR "install test: ${header} includes ${bad}")
  endif()
endforeach()

# No build type: the consumer's one file compiles unoptimized (faster); the simulation runs in the
# installed, optimized libraries.
set(launcher "")
if(LAUNCHER)
  set(launcher -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
run("configure the consumer" ${CMAKE_COMMAND} -S ${CONSUMER_DIR} -B ${WORK_DIR}/consumer-build -G ${GENERATOR}
    -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_PREFIX_PATH=${prefix} ${launcher})
run("build the consumer" ${CMAKE_COMMAND} --build ${WORK_DIR}/consumer-build)
file(REMOVE_RECURSE ${WORK_DIR}/run)
# The built-in maps from the prefix (fleetmap_MAPS_DIR), as a program finds them without the source tree.
run("run the consumer" ${CMAKE_COMMAND} -E env FLEETMAP_MAPS_DIR=${prefix}/share/fleetmap/maps
    ${WORK_DIR}/consumer-build/consumer ${WORK_DIR}/run)

# The Python package from the prefix: it imports from there and finds the installed maps.
if(PYTHON)
  run("import the installed Python package" ${CMAKE_COMMAND} -E env PYTHONPATH=${prefix}/${PYTHON_DIR} FLEETMAP_MAPS_DIR=
      ${PYTHON} -c "import fleetmap, os, sys; assert fleetmap.__file__.startswith(sys.argv[1]), fleetmap.__file__; \
assert os.environ['FLEETMAP_MAPS_DIR'].startswith(sys.argv[1]); print(fleetmap.load_map('office'))" ${prefix})
endif()
