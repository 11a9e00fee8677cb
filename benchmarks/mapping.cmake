# Evaluation programs of the mapping module (*_eval.cpp print JSON). Include from
# benchmarks/CMakeLists.txt after pitchlab_all_modules is set:  include(mapping.cmake)
find_package(nlohmann_json 3 REQUIRED)
foreach(name registration_eval real_eval loop_closure_eval)
  add_executable(${name} "${CMAKE_CURRENT_LIST_DIR}/${name}.cpp")
  target_link_libraries(${name} PRIVATE ${pitchlab_all_modules} nlohmann_json::nlohmann_json)
  target_compile_options(${name} PRIVATE -Wall -Wextra -Wpedantic)
  target_compile_definitions(${name} PRIVATE PITCHLAB_WORLDS_DIR="${PITCHLAB_WORLDS_BUILD_DIR}")
  if(TARGET pitchlab_world_files)
    add_dependencies(${name} pitchlab_world_files)
  endif()
endforeach()
target_sources(real_eval PRIVATE "${CMAKE_CURRENT_LIST_DIR}/real_map_check.cpp"
  "${CMAKE_CURRENT_LIST_DIR}/real_wrong_priors.cpp")
# real_eval reports line pitch as the commands do (mission/registration_json.hpp).
target_link_libraries(real_eval PRIVATE pitchlab::mission)
