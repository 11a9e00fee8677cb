#include "pitchlab/hw/pitch_unit_driver.hpp"

#include <cmath>
#include <stdexcept>
#include <thread>

#include "pitchlab/hw/stop_request.hpp"

namespace pitchlab::hw {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;
constexpr double kPi = 3.14159265358979323846;

}  // namespace

void PitchUnitDriverConfig::Validate() const {
  if (device.empty()) throw std::invalid_argument("pitch_unit.device is empty");
  if (!IsSupportedBaud(baud)) {
    throw std::invalid_argument("pitch_unit.baud = " + std::to_string(baud) +
                                " is invalid (9600, 19200, 38400, 115200, 500000)");
  }
  unit.Validate();
  if (reply_timeout_ms <= 0 || retries < 1 || poll_period_ms <= 0) {
    throw std::invalid_argument("pitch_unit.reply_timeout_ms / retries / poll_period_ms = " +
                                std::to_string(reply_timeout_ms) + " / " + std::to_string(retries) +
                                " / " + std::to_string(poll_period_ms) + " are invalid (> 0)");
  }
}

PitchUnitDriver::PitchUnitDriver(const PitchUnitDriverConfig& config)
    : config_(config), model_((config.Validate(), config.unit)) {
  port_ = std::make_unique<SerialPort>(config_.device, config_.baud);
  Result<pitch::Frame> reply = Request({pitch::kPing, {}});
  Result<pitch::Info> info =
      reply ? pitch::DecodeInfo(*reply) : Result<pitch::Info>(tl::make_unexpected(reply.error()));
  if (!info) {
    throw std::runtime_error("pitch unit on " + config_.device + ": no answer to PING (" +
                             info.error().message + ")");
  }
  info_ = *info;
  const long step_cdeg = std::lround(config_.unit.step_deg * 100.0);
  if (info_.step_cdeg != step_cdeg) {
    throw std::runtime_error(
        "pitch unit on " + config_.device + " steps " + std::to_string(info_.step_cdeg / 100.0) +
        " deg but pitch_unit.step_deg = " + std::to_string(config_.unit.step_deg));
  }
  if (long(info_.counts_per_rev) != config_.unit.encoder_counts_per_rev) {
    throw std::runtime_error("pitch unit on " + config_.device + " has " +
                             std::to_string(info_.counts_per_rev) +
                             " counts/rev but pitch_unit.encoder_counts_per_rev = " +
                             std::to_string(config_.unit.encoder_counts_per_rev));
  }
}

double PitchUnitDriver::Angle(std::int32_t count) const {
  return double(count) * 2.0 * kPi / double(info_.counts_per_rev);
}

Result<pitch::Frame> PitchUnitDriver::Request(const pitch::Frame& request) {
  Error last{Error::Code::kTimeout, "no reply"};
  std::uint8_t buffer[256];
  for (int attempt = 0; attempt < config_.retries; ++attempt) {
    if (StopRequested()) return tl::make_unexpected(StopError("pitch unit on " + config_.device));
    if (attempt > 0) ++retries_;
    port_->DiscardInput();
    reader_.Clear();
    if (Result<void> sent = port_->Write(pitch::Encode(request)); !sent) {
      return tl::make_unexpected(sent.error());
    }
    const auto deadline = Clock::now() + milliseconds(config_.reply_timeout_ms);
    for (;;) {
      if (StopRequested()) {
        return tl::make_unexpected(StopError("pitch unit on " + config_.device));
      }
      if (auto frame = reader_.Next()) {
        if (frame->command == (request.command | pitch::kReplyBit)) return *frame;
        if (frame->command == pitch::kErrorReply) {
          last = {Error::Code::kProtocol,
                  "device reported error " +
                      std::to_string(frame->payload.empty() ? 0 : frame->payload[0])};
          break;
        }
        continue;  // stale reply
      }
      const auto left = std::chrono::duration_cast<milliseconds>(deadline - Clock::now());
      if (left.count() <= 0) {
        last = {Error::Code::kTimeout,
                "no reply within " + std::to_string(config_.reply_timeout_ms) + " ms"};
        break;
      }
      Result<std::size_t> n = port_->Read(buffer, sizeof(buffer), left);
      if (!n && n.error().code == Error::Code::kDevice) {
        return Fail(Error::Code::kDevice,
                    "pitch unit on " + config_.device + ": " + n.error().message);
      }
      if (n) reader_.Feed(buffer, *n);
    }
  }
  return Fail(last.code, "pitch unit on " + config_.device + ": request " +
                             std::to_string(request.command) + " failed after " +
                             std::to_string(config_.retries) + " attempts: " + last.message);
}

Result<double> PitchUnitDriver::MoveTo(double pitch_rad, milliseconds timeout) {
  if (!std::isfinite(pitch_rad)) return Fail(Error::Code::kInvalidArgument, "pitch is not finite");
  const auto deadline = Clock::now() + timeout;
  const std::int16_t step = std::int16_t(model_.StepFor(pitch_rad));
  Result<pitch::Frame> moved = Request(pitch::MoveRequest(step));
  if (!moved) return tl::make_unexpected(moved.error());
  Result<std::int16_t> target = pitch::DecodeMoveReply(*moved);
  if (!target) return tl::make_unexpected(target.error());
  for (;;) {
    Result<pitch::Frame> reply = Request({pitch::kStatus, {}});
    if (!reply) return tl::make_unexpected(reply.error());
    Result<pitch::Status> status = pitch::DecodeStatus(*reply);
    if (!status) return tl::make_unexpected(status.error());
    if (status->flags & pitch::kFault) {
      return Fail(Error::Code::kDevice,
                  "pitch unit on " + config_.device + " reports a servo fault");
    }
    // Settled at our target (a MOVE whose reply was lost and re-sent is idempotent).
    if ((status->flags & pitch::kSettled) && status->target == *target) return Angle(status->count);
    if (Clock::now() >= deadline) {
      return Fail(Error::Code::kTimeout, "pitch unit on " + config_.device +
                                             " not settled at step " + std::to_string(*target) +
                                             " within " + std::to_string(timeout.count()) + " ms");
    }
    std::this_thread::sleep_for(milliseconds(config_.poll_period_ms));
  }
}

Result<double> PitchUnitDriver::ReadEncoder() {
  Result<pitch::Frame> reply = Request({pitch::kEncoder, {}});
  if (!reply) return tl::make_unexpected(reply.error());
  Result<std::int32_t> count = pitch::DecodeEncoder(*reply);
  if (!count) return tl::make_unexpected(count.error());
  return Angle(*count);
}

}  // namespace pitchlab::hw
