# `cmake --install build --prefix P`: the libraries and their headers (pitchlab_add_library), the
# pitchlab program (apps/), the built-in worlds (worlds/) and this CMake package, so that a user's project
# does find_package(pitchlab) and links pitchlab::mission (examples/).
include(CMakePackageConfigHelpers)

set(PITCHLAB_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/pitchlab")

install(EXPORT pitchlabTargets NAMESPACE pitchlab:: DESTINATION "${PITCHLAB_INSTALL_CMAKEDIR}")
configure_package_config_file(cmake/pitchlabConfig.cmake.in
  "${CMAKE_CURRENT_BINARY_DIR}/pitchlabConfig.cmake"
  INSTALL_DESTINATION "${PITCHLAB_INSTALL_CMAKEDIR}"
  PATH_VARS PITCHLAB_INSTALL_WORLDSDIR)
write_basic_package_version_file("${CMAKE_CURRENT_BINARY_DIR}/pitchlabConfigVersion.cmake"
  COMPATIBILITY SameMinorVersion)
install(FILES "${CMAKE_CURRENT_BINARY_DIR}/pitchlabConfig.cmake"
              "${CMAKE_CURRENT_BINARY_DIR}/pitchlabConfigVersion.cmake"
        DESTINATION "${PITCHLAB_INSTALL_CMAKEDIR}")
