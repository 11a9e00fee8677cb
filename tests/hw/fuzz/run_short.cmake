# cmake -DSOURCE_DIR=<tests/hw/fuzz> -DBINARY_DIR=<dir> -DCXX=<clang++> [-DRUNS=20000] -P run_short.cmake
# Configures and builds the decoders' fuzzers with clang in BINARY_DIR (incremental on later
# runs), then runs each for RUNS inputs with a fixed seed, from corpus/<fuzzer>/ where there is
# one. Prints "SKIP: ..." and exits 0 when clang cannot link a fuzzer (no libclang-rt; CTest's
# SKIP_REGULAR_EXPRESSION marks the test skipped), exits non-zero on a build failure or a finding.
foreach(var SOURCE_DIR BINARY_DIR CXX)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_short.cmake: -D${var}=... is required")
  endif()
endforeach()
if(NOT DEFINED RUNS)
  set(RUNS 20000)
endif()
# A bound on each fuzzer's wall time whatever the machine: CI's 2 cores share the job with the
# rest of the tests (20000 runs take a few seconds on a free core).
if(NOT DEFINED MAX_SECONDS)
  set(MAX_SECONDS 25)
endif()
include("${SOURCE_DIR}/fuzz_sources.cmake")
set(fuzzers ${PITCHLAB_FUZZERS})

# Can clang link a fuzzer at all? (clang without its runtime is "not present" for this test.)
file(MAKE_DIRECTORY "${BINARY_DIR}/probe")
file(WRITE "${BINARY_DIR}/probe/probe.cpp"
     "#include <cstddef>\n#include <cstdint>\n"
     "extern \"C\" int LLVMFuzzerTestOneInput(const std::uint8_t*, std::size_t) { return 0; }\n")
execute_process(COMMAND "${CXX}" -fsanitize=fuzzer,address,undefined probe.cpp -o probe
                WORKING_DIRECTORY "${BINARY_DIR}/probe" RESULT_VARIABLE probe_rc
                OUTPUT_VARIABLE probe_out ERROR_VARIABLE probe_out)
if(NOT probe_rc EQUAL 0)
  message("SKIP: ${CXX} cannot link a libFuzzer target (install libclang-rt-dev):\n${probe_out}")
  return()
endif()

execute_process(COMMAND "${CMAKE_COMMAND}" -S "${SOURCE_DIR}" -B "${BINARY_DIR}/build"
                        -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_BUILD_TYPE=
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the fuzzers failed")
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" --build "${BINARY_DIR}/build" -j2 RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building the fuzzers failed")
endif()

set(failed "")
foreach(fuzzer ${fuzzers})
  message("hw_${fuzzer}_fuzz: ${RUNS} runs, at most ${MAX_SECONDS} s")
  # A seed corpus (corpus/<fuzzer>/) is read from the sources; what the run adds goes to a folder
  # of the build (libFuzzer writes into the first folder it is given).
  set(corpus "")
  if(IS_DIRECTORY "${SOURCE_DIR}/corpus/${fuzzer}")
    file(REMOVE_RECURSE "${BINARY_DIR}/corpus/${fuzzer}")
    file(MAKE_DIRECTORY "${BINARY_DIR}/corpus/${fuzzer}")
    set(corpus "${BINARY_DIR}/corpus/${fuzzer}" "${SOURCE_DIR}/corpus/${fuzzer}")
  endif()
  execute_process(COMMAND "${BINARY_DIR}/build/hw_${fuzzer}_fuzz" -runs=${RUNS} -seed=1
                          -max_total_time=${MAX_SECONDS} ${corpus}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  string(REGEX MATCH "Done [0-9]+ runs in [0-9]+ second\\(s\\)" done "${out}")
  message("  ${done} (exit ${rc})")
  if(NOT rc EQUAL 0)
    message("${out}")
    list(APPEND failed ${fuzzer})
  endif()
endforeach()
if(failed)
  message(FATAL_ERROR "fuzzers that found a crash: ${failed}")
endif()
