# `cmake --install build --prefix P` gives a CMake package: P/include/fleetmap/<module>/*.h, the
# static libraries in P/lib, and P/lib/cmake/fleetmap (fleetmapConfig.cmake and the exported
# targets fleetmap::fleetmap, fleetmap::core, fleetmap::mapping, ...).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# The modules a program can link, lowest layer first (DESIGN.md §1). The CLI is not among them.
set(FLEETMAP_MODULES core mapping io viz maps localization merging planning exploration sim sweep experiments)

# Headers that stay inside the build: they use third-party types (cv::Mat, YAML::Node,
# nlohmann::json) in their declarations, and only fleetmap's own sources and the CLI need them.
# The pictures (viz/, the run, sweep and experiment reports) are OpenCV images throughout.
set(FLEETMAP_INTERNAL_HEADERS
  sim/video_module.h io/yaml_reader.h io/file_kind.h io/map_image.h maps/generated_maps.h merging/grid_level.h merging/hamming.h mapping/state_mask.h sim/scenario_yaml.h sim/run_output.h sim/run_replay.h
  sweep/sweep_report.h experiments/slam_output.h experiments/corridor_output.h)
file(GLOB viz_headers RELATIVE ${PROJECT_SOURCE_DIR} CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/viz/*.h)
list(APPEND FLEETMAP_INTERNAL_HEADERS ${viz_headers})

set(FLEETMAP_INSTALL_MAPSDIR ${CMAKE_INSTALL_DATADIR}/fleetmap/maps)
set(FLEETMAP_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/fleetmap)

set(public_headers "")
foreach(module IN LISTS FLEETMAP_MODULES)
  file(GLOB headers RELATIVE ${PROJECT_SOURCE_DIR} CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/${module}/*.h)
  list(APPEND public_headers ${headers})
  # Position-independent: the libraries go into the Python extension and consumers' shared libraries.
  set_target_properties(fleetmap_${module} PROPERTIES EXPORT_NAME ${module} POSITION_INDEPENDENT_CODE ON)
  add_library(fleetmap::${module} ALIAS fleetmap_${module})
endforeach()
if(FLEETMAP_INTERNAL_HEADERS)
  list(REMOVE_ITEM public_headers ${FLEETMAP_INTERNAL_HEADERS})
endif()
list(SORT public_headers)

# The staged copy (includes spelled "fleetmap/<module>/...") is rebuilt when a header changes.
set(stage_dir ${PROJECT_BINARY_DIR}/include)
set(stage_list ${PROJECT_BINARY_DIR}/fleetmap_public_headers.txt)
set(stage_stamp ${PROJECT_BINARY_DIR}/fleetmap_public_headers.stamp)
list(JOIN public_headers "\n" list_text)
file(CONFIGURE OUTPUT ${stage_list} CONTENT "${list_text}\n")
list(JOIN FLEETMAP_MODULES "|" modules_alternation)
list(TRANSFORM public_headers PREPEND ${PROJECT_SOURCE_DIR}/ OUTPUT_VARIABLE public_header_paths)
add_custom_command(
  OUTPUT ${stage_stamp}
  COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR} -DOUTPUT_DIR=${stage_dir} -DLIST_FILE=${stage_list}
          "-DMODULES=${modules_alternation}" -DSTAMP=${stage_stamp} -P ${PROJECT_SOURCE_DIR}/cmake/StageHeaders.cmake
  DEPENDS ${public_header_paths} ${stage_list} ${PROJECT_SOURCE_DIR}/cmake/StageHeaders.cmake
  COMMENT "Staging fleetmap's public headers for installation"
  VERBATIM)
add_custom_target(fleetmap_public_headers ALL DEPENDS ${stage_stamp})

# fleetmap::fleetmap: every module.
add_library(fleetmap_library INTERFACE)
set_target_properties(fleetmap_library PROPERTIES EXPORT_NAME fleetmap)
foreach(module IN LISTS FLEETMAP_MODULES)
  target_link_libraries(fleetmap_library INTERFACE fleetmap_${module})
endforeach()
add_library(fleetmap::fleetmap ALIAS fleetmap_library)

list(TRANSFORM FLEETMAP_MODULES PREPEND fleetmap_ OUTPUT_VARIABLE module_targets)
install(TARGETS ${module_targets} fleetmap_library EXPORT fleetmapTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${stage_dir}/fleetmap DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# The video module RunVideo loads (sim/video_module.h): P/lib/fleetmap, which an installed program
# finds from P/bin, and the configured prefix's is baked into the library.
install(TARGETS fleetmap_video LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/fleetmap)
install(EXPORT fleetmapTargets NAMESPACE fleetmap:: DESTINATION ${FLEETMAP_INSTALL_CMAKEDIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/fleetmapConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/fleetmapConfig.cmake
                              INSTALL_DESTINATION ${FLEETMAP_INSTALL_CMAKEDIR}
                              PATH_VARS FLEETMAP_INSTALL_MAPSDIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/fleetmapConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/fleetmapConfig.cmake ${PROJECT_BINARY_DIR}/fleetmapConfigVersion.cmake
        DESTINATION ${FLEETMAP_INSTALL_CMAKEDIR})
