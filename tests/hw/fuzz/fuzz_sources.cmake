# What each libFuzzer target compiles besides its harness (tests/hw/fuzz/<fuzzer>_fuzz.cpp), for
# the in-tree build (tests/hw/CMakeLists.txt) and the small clang project (fuzz/CMakeLists.txt):
# a hw decoder's protocol source, or for `cloud` sensors' cloud file readers, which need nothing
# of the module's simulation (MuJoCo, Embree).
set(PITCHLAB_FUZZERS lms200 pitch_unit p2os cloud)

function(pitchlab_fuzz_sources fuzzer root out_var)
  if(fuzzer STREQUAL "cloud")
    set(sources scan_pcd pcd_checks pcd_data cloud_text cloud_file cloud_3dtk cloud_ply cloud_xyz)
    list(TRANSFORM sources PREPEND "${root}/sensors/src/")
    list(TRANSFORM sources APPEND ".cpp")
  else()
    set(sources "${root}/hw/src/${fuzzer}_protocol.cpp")
  endif()
  set(${out_var} ${sources} PARENT_SCOPE)
endfunction()
