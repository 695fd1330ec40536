# The installed package: `cmake --install BUILD --prefix PREFIX` puts the public headers
# (include/parapm/engine.h, client.h), the engine headers they include (under
# include/parapm/engine/, which the targets add to the include path), the static libraries and
# lib/cmake/ParaPM/, so that another project writes
#   find_package(ParaPM REQUIRED)
#   target_link_libraries(app PRIVATE ParaPM::engine)   # ParaPM::openmesh for the OpenMesh
#                                                         # adapters, ParaPM::client for gRPC
# tests/package/ builds examples/cpp against a fresh prefix.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(PARAPM_ENGINE_LIBRARIES parapm_mesh parapm_io parapm_pm parapm_simplify parapm_partition
  parapm_measure parapm_parallel parapm_engine)
# What include/parapm/engine.h includes, and what they include (g++ -MM of engine.h).
set(PARAPM_ENGINE_HEADERS io/gltf_writer.h io/mesh_io.h mesh/mesh.h mesh/repair.h
  parallel/edge_keys.h parallel/parallel_build.h parallel/simplify_subset.h parallel/subset_job.h
  pm/face_lists.h pm/levels.h pm/pm_file.h pm/progressive_mesh.h simplify/collapse_mesh.h
  simplify/module_state.h
  simplify/copy_groups.h simplify/key_rank.h simplify/modules.h simplify/quad_heap.h
  simplify/quadric.h
  simplify/simplifier.h simplify/tiered_queue.h
  simplify/simplify.h util/chunked_loops.h util/error.h util/fresh_pages.h util/progress.h
  util/zeroed_array.h)

install(TARGETS ${PARAPM_ENGINE_LIBRARIES} parapm_openmesh EXPORT ParaPMTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(FILES include/parapm/engine.h include/parapm/openmesh.h
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/parapm)
foreach(header ${PARAPM_ENGINE_HEADERS})
  get_filename_component(folder ${header} DIRECTORY)
  install(FILES engine/${header} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/parapm/engine/${folder})
endforeach()

set(PARAPM_WITH_CLIENT OFF)
if(PARAPM_BUILD_SERVICE)
  set(PARAPM_WITH_CLIENT ON)
  install(TARGETS parapm_proto parapm_rpc_client parapm_client EXPORT ParaPMTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(FILES include/parapm/client.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/parapm)
  install(FILES ${PROJECT_BINARY_DIR}/proto/parapm.pb.h ${PROJECT_BINARY_DIR}/proto/parapm.grpc.pb.h
    proto/parapm.proto DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/parapm/proto)
endif()

install(EXPORT ParaPMTargets NAMESPACE ParaPM:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/ParaPM)
configure_package_config_file(cmake/ParaPMConfig.cmake.in
  ${PROJECT_BINARY_DIR}/ParaPMConfig.cmake INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/ParaPM)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/ParaPMConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/ParaPMConfig.cmake ${PROJECT_BINARY_DIR}/ParaPMConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/ParaPM)
