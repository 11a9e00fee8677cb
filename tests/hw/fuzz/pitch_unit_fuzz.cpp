// libFuzzer: the pitch-unit frame reader and reply decoders on arbitrary bytes.
#include <cstdlib>

#include "pitchlab/hw/pitch_unit_protocol.hpp"

using namespace pitchlab::hw::pitch;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FrameReader reader;
  reader.Feed(data, size);
  while (auto frame = reader.Next()) {
    (void)DecodeInfo(*frame);
    (void)DecodeStatus(*frame);
    (void)DecodeEncoder(*frame);
    (void)DecodeMoveReply(*frame);
    const auto bytes = Encode(*frame);
    FrameReader again;
    again.Feed(bytes.data(), bytes.size());
    auto back = again.Next();
    if (!back || !(*back == *frame)) std::abort();
  }
  return 0;
}
