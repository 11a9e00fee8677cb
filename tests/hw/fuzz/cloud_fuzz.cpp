// libFuzzer: arbitrary bytes as a cloud file through sensors::ReadCloudFile, its format picked by
// the first byte (.pcd, .ply, .xyz, or .3d with a valid .pose beside it). Never a crash, a
// sanitizer report or a read out of bounds, and the reader's contract holds (cloud_input.hpp:
// finite points, pose and sensor origin; an error names the file), else it prints what broke and
// aborts, which libFuzzer reports as a failure. Files users bring are untrusted input as much as
// a serial line is. Seeds: corpus/cloud/ (one file of each format and encoding), which
// tests/hw/cloud_fuzz_contract_test.cpp also reads.
// Its first 5 minutes found a DATA line without a newline read from offset -1 (std::length_error).
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "cloud_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string stem = "/dev/shm/pitchlab_cloud_fuzz_" + std::to_string(::getpid());
  const std::string path = pitchlab::fuzz::WriteCloudInput(data, size, stem);
  if (path.empty()) return 0;
  const std::string breach =
      pitchlab::fuzz::CloudContractBreach(pitchlab::sensors::ReadCloudFile(path), path);
  if (!breach.empty()) {
    std::fprintf(stderr, "cloud reader contract broken: %s\n", breach.c_str());
    std::abort();
  }
  return 0;
}
