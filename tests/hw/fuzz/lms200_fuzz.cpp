// libFuzzer: arbitrary bytes through the LMS200 reader and measured-value decoder must never
// crash, and every telegram the reader accepts must re-encode to the same bytes.
#include <cstdlib>

#include "pitchlab/hw/lms200_protocol.hpp"

using namespace pitchlab::hw::lms200;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  for (std::uint8_t side : {std::uint8_t(0x80), std::uint8_t(0x00)}) {
    TelegramReader reader(side);
    reader.Feed(data, size);
    while (auto event = reader.Next()) {
      if (event->kind != ReaderEvent::Kind::kTelegram) continue;
      const auto bytes = Encode(event->telegram);
      auto back = Decode(bytes.data(), bytes.size());
      if (!back || !(*back == event->telegram)) std::abort();
      if (auto mv = DecodeMeasuredValues(event->telegram)) {
        for (std::uint16_t v : mv->values) (void)DecodeReading(v, mv->units);
      }
    }
  }
  (void)Decode(data, size);
  return 0;
}
