// libFuzzer: the P2OS packet reader, SIP decoder and command-argument parser on arbitrary bytes.
#include <cstdlib>

#include "pitchlab/hw/p2os_protocol.hpp"

using namespace pitchlab::hw::p2os;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  PacketReader reader;
  reader.Feed(data, size);
  while (auto payload = reader.Next()) {
    (void)DecodeSip(*payload);
    (void)CommandArgument(*payload);
    const auto bytes = Encode(*payload);
    PacketReader again;
    again.Feed(bytes.data(), bytes.size());
    auto back = again.Next();
    if (!back || *back != *payload) std::abort();
  }
  return 0;
}
