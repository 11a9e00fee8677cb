include(GNUInstallDirs)

# pitchlab_add_library(<module> [PUBLIC_DEPS ...] [PRIVATE_DEPS ...])
# One static library per top-level module: sources are <module>/src/*.cpp, public headers
# <module>/include/pitchlab/<module>/*.hpp; the target is pitchlab_<module>, alias pitchlab::<module>.
function(pitchlab_add_library module)
  cmake_parse_arguments(ARG "" "" "PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  file(GLOB sources CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/src/*.cpp")
  add_library(pitchlab_${module} STATIC ${sources})
  add_library(pitchlab::${module} ALIAS pitchlab_${module})
  target_include_directories(pitchlab_${module}
    PUBLIC "$<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>"
           "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>"
    PRIVATE "${CMAKE_CURRENT_SOURCE_DIR}/src")
  target_link_libraries(pitchlab_${module} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  target_compile_options(pitchlab_${module} PRIVATE -Wall -Wextra -Wpedantic)
  set_target_properties(pitchlab_${module} PROPERTIES POSITION_INDEPENDENT_CODE ON
                        EXPORT_NAME ${module})
  # Installed with its public headers into the package pitchlab::<module> (cmake/Install.cmake).
  install(TARGETS pitchlab_${module} EXPORT pitchlabTargets
          ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}")
  install(DIRECTORY "${CMAKE_CURRENT_SOURCE_DIR}/include/" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}")
endfunction()

# pitchlab_add_test(<name> SOURCES ... DEPS ...): one GoogleTest binary, its cases registered in CTest.
function(pitchlab_add_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main GTest::gmock)
  target_compile_definitions(${name} PRIVATE
    PITCHLAB_TEST_DATA_DIR="${PITCHLAB_TEST_DATA_SOURCE_DIR}"
    PITCHLAB_WORLDS_DIR="${PITCHLAB_WORLDS_BUILD_DIR}"
    PITCHLAB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 600)
endfunction()
