#include "pitchlab/hw/pitch_unit_emulator.hpp"

#include <chrono>
#include <cmath>

namespace pitchlab::hw {
namespace {

constexpr double kPi = 3.14159265358979323846;

double NowS() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

PitchUnitEmulator::PitchUnitEmulator(const sensors::PitchUnitConfig& config, int baud,
                                     PitchPhysics physics, std::string link_path)
    : EmulatedDevice("pitch_unit", baud, std::move(link_path)),
      model_(config),
      physics_(std::move(physics)) {
  Start();
}

PitchUnitEmulator::~PitchUnitEmulator() { Stop(); }

std::int32_t PitchUnitEmulator::Count(double angle_rad) const {
  return std::int32_t(
      std::lround(angle_rad / (2.0 * kPi / model_.config().encoder_counts_per_rev)));
}

std::pair<double, bool> PitchUnitEmulator::State() {
  if (physics_.state) return physics_.state();
  const double elapsed_s = NowS() - move_start_s_;
  const double total_s = model_.MoveTime(start_rad_, target_rad_);
  const double slew_s = total_s - model_.config().settle_s;
  if (elapsed_s >= total_s) return {target_rad_, false};
  const double f = slew_s > 0 ? std::min(1.0, elapsed_s / slew_s) : 1.0;
  return {start_rad_ + f * (target_rad_ - start_rad_), true};
}

void PitchUnitEmulator::OnBytes(const std::uint8_t* bytes, std::size_t size) {
  if (!DriverBaudMatches()) {
    CountRequest(false);
    return;
  }
  reader_.Feed(bytes, size);
  while (auto frame = reader_.Next()) {
    if (reader_.crc_errors() != crc_errors_seen_) {
      crc_errors_seen_ = reader_.crc_errors();
      CountRequest(false);
      Send(pitch::Encode({pitch::kErrorReply, {pitch::kBadCrc}}));
    }
    CountRequest(true);
    Handle(*frame);
  }
}

void PitchUnitEmulator::Handle(const pitch::Frame& request) {
  const auto& p = request.payload;
  const double step_rad = model_.config().step_deg * kPi / 180.0;
  switch (request.command) {
    case pitch::kPing: {
      if (!p.empty()) break;
      pitch::Info info;
      info.step_cdeg = std::uint16_t(std::lround(model_.config().step_deg * 100.0));
      info.counts_per_rev = std::uint32_t(model_.config().encoder_counts_per_rev);
      info.min_step = std::int16_t(model_.StepFor(-1e9));
      info.max_step = std::int16_t(model_.StepFor(1e9));
      Send(pitch::Encode(pitch::EncodeInfo(info)));
      return;
    }
    case pitch::kMove: {
      if (p.size() != 2) break;
      const std::int16_t wanted = std::int16_t(p[0] | (p[1] << 8));
      target_step_ = std::int16_t(model_.StepFor(wanted * step_rad));
      clamped_ = target_step_ != wanted;
      const std::uint8_t flags = std::uint8_t(pitch::kMoving | (clamped_ ? pitch::kClamped : 0));
      pitch::Frame reply{pitch::kMove | pitch::kReplyBit, {}};
      reply.payload = {std::uint8_t(target_step_ & 0xFF), std::uint8_t(target_step_ >> 8), flags};
      start_rad_ = State().first;
      target_rad_ = model_.StepAngle(target_step_);
      move_start_s_ = NowS();
      Send(pitch::Encode(reply));
      if (physics_.command) physics_.command(target_rad_);
      return;
    }
    case pitch::kEncoder: {
      if (!p.empty()) break;
      const std::uint32_t count = std::uint32_t(Count(State().first));
      Send(pitch::Encode({pitch::kEncoder | pitch::kReplyBit,
                          {std::uint8_t(count), std::uint8_t(count >> 8), std::uint8_t(count >> 16),
                           std::uint8_t(count >> 24)}}));
      return;
    }
    case pitch::kStatus: {
      if (!p.empty()) break;
      const auto [angle_rad, moving] = State();
      pitch::Status status;
      status.flags = std::uint8_t((moving ? pitch::kMoving : pitch::kSettled) |
                                  (clamped_ ? pitch::kClamped : 0));
      status.target = target_step_;
      status.count = Count(angle_rad);
      Send(pitch::Encode(pitch::EncodeStatus(status)));
      return;
    }
    default:
      Send(pitch::Encode({pitch::kErrorReply, {pitch::kUnknownCommand}}));
      return;
  }
  Send(pitch::Encode({pitch::kErrorReply, {pitch::kBadLength}}));
}

}  // namespace pitchlab::hw
