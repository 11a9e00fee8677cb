# Run as: cmake -DBUILD_DIR=... -DEXAMPLE_DIR=... -DWORK_DIR=... -DBUILD_TREE_WORLDS=...
#   -DDEM_FILE=... (an .asc with its .prj) -P this
#   [-DTREE_CXX_FLAGS=... -DTREE_EXE_LINKER_FLAGS=...: the flags the installed tree was built with]
cmake_minimum_required(VERSION 3.22)

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "${what} failed (${code}):\n${out}\n${err}")
  endif()
  set(last_output "${out}${err}" PARENT_SCOPE)
endfunction()

function(expect condition message)
  if(NOT (${condition}))
    message(FATAL_ERROR "${message}")
  endif()
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
run("cmake --install" ${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}")

# What the package promises, and nothing of the build tree in it.
foreach(file bin/pitchlab bin/pitchlab_worldgen include/pitchlab/mission/sim_mission.hpp
        include/pitchlab/sensors/scan3d.hpp share/pitchlab/worlds/office.xml
        share/pitchlab/worlds/terrain_hfield.bin lib/cmake/pitchlab/pitchlabConfig.cmake)
  expect("EXISTS;${prefix}/${file}" "the install has no ${file}")
endforeach()
# The worlds folder holds worlds and their height fields, nothing of the build.
file(GLOB installed_worlds RELATIVE "${prefix}/share/pitchlab/worlds"
     "${prefix}/share/pitchlab/worlds/*")
foreach(name ${installed_worlds})
  expect("name;MATCHES;^[a-z0-9_]+(\\.xml|_hfield\\.bin)$"
         "share/pitchlab/worlds holds ${name}, which is no world file")
endforeach()
file(GLOB package_files "${prefix}/lib/cmake/pitchlab/*.cmake")
foreach(f ${package_files})
  file(READ "${f}" text)
  string(FIND "${text}" "${BUILD_DIR}" at)
  expect("at;EQUAL;-1" "${f} names the build tree ${BUILD_DIR}")
endforeach()

# The installed program finds the installed worlds (no PITCHLAB_WORLDS_DIR, the build's hidden
# from it by name: it reports the folder it reads).
set(ENV{PITCHLAB_WORLDS_DIR} "")
run("installed pitchlab worlds" "${prefix}/bin/pitchlab" worlds --json)
string(FIND "${last_output}" "${prefix}/share/pitchlab/worlds" at)
expect("NOT;at;EQUAL;-1" "installed `pitchlab worlds` does not read ${prefix}/share/pitchlab/worlds:\n${last_output}")

# The installed world maker makes a world of a user's DEM, and the installed program runs on it.
set(dem_world "${WORK_DIR}/my_worlds/escarpment.xml")
run("installed pitchlab_worldgen dem" "${prefix}/bin/pitchlab_worldgen" dem --in "${DEM_FILE}"
    --cell 2 --out "${dem_world}")
expect("EXISTS;${WORK_DIR}/my_worlds/escarpment_hfield.bin" "pitchlab_worldgen wrote no height field")
run("installed pitchlab scan of the DEM world" "${prefix}/bin/pitchlab" scan --world "${dem_world}"
    --out "${WORK_DIR}/my_worlds/scan.pcd")
expect("EXISTS;${WORK_DIR}/my_worlds/scan.pcd" "pitchlab scan wrote no scan of the DEM world")

# A user's project: configure and build examples/ against the prefix only. It is built with the
# flags the installed libraries were built with, as a user of such a package must: the libraries
# are static, so an instrumented tree (scripts/sanitize.sh) installs objects that call ASan's
# runtime (__asan_init) and link only with -fsanitize, and Eigen's allocator must agree on
# EIGEN_MALLOC_ALREADY_ALIGNED across the library and the program that frees its matrices.
run("configure examples/" ${CMAKE_COMMAND} -S "${EXAMPLE_DIR}" -B "${WORK_DIR}/example"
    -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${prefix}"
    "-DCMAKE_CXX_FLAGS=${TREE_CXX_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${TREE_EXE_LINKER_FLAGS}")
run("build examples/" ${CMAKE_COMMAND} --build "${WORK_DIR}/example")

# A goal that is no number is the user's mistake: exit 2 with the usage, before any work.
execute_process(COMMAND "${WORK_DIR}/example/run_mission" office east 0 "${WORK_DIR}/bad"
                RESULT_VARIABLE code ERROR_VARIABLE err)
expect("code;EQUAL;2;AND;err;MATCHES;usage" "a goal of 'east' gave ${code}: ${err}")
expect("NOT;EXISTS;${WORK_DIR}/bad" "a refused run left ${WORK_DIR}/bad")

# A short office mission: from the default start (-8, 0) 3 m along the open floor to (-5, 0)
# (4 stops, ~80 s simulated, ~5 s of wall time).
set(run_dir "${WORK_DIR}/run")
run("run_mission" "${WORK_DIR}/example/run_mission" office -5 0 "${run_dir}")
string(FIND "${last_output}" "world ${prefix}/share/pitchlab/worlds/office.xml," at)
expect("NOT;at;EQUAL;-1" "run_mission did not run the installed office.xml:\n${last_output}")
string(FIND "${last_output}" "success: goal reached" at)
expect("NOT;at;EQUAL;-1" "run_mission did not say it reached the goal:\n${last_output}")
string(FIND "${last_output}" "run folder ${run_dir}" at)
expect("NOT;at;EQUAL;-1" "run_mission did not name its run folder:\n${last_output}")
foreach(file metrics.json config.yaml report.html map_cloud.pcd stops/000/scan.pcd stops/000/registration.json)
  expect("EXISTS;${run_dir}/${file}" "the run folder has no ${file}")
endforeach()
file(READ "${run_dir}/metrics.json" metrics)
string(JSON success GET "${metrics}" success)
expect("success" "metrics.json says the run failed:\n${metrics}")
string(JSON world GET "${metrics}" world)
expect("world;STREQUAL;office" "metrics.json names the world '${world}', not office")
message(STATUS "installed tree: pitchlab, package, worlds; example built and reached its goal")
