#include "pitchlab/hw/p2os_driver.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "pitchlab/hw/stop_request.hpp"

namespace pitchlab::hw {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;
constexpr double kPi = 3.14159265358979323846;
constexpr milliseconds kHandshakeTimeout{500};
constexpr milliseconds kPulsePeriod{500};  // well inside the robot's 2 s watchdog

double SteadyNowS() {
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

// Difference of two 15-bit wrapping positions, in (-2^14, 2^14].
int Wrap15(int delta) {
  delta &= 0x7FFF;
  return delta > 0x4000 ? delta - 0x8000 : delta;
}

}  // namespace

void P2osDriverConfig::Validate() const {
  if (device.empty()) throw std::invalid_argument("base.device is empty");
  if (!IsSupportedBaud(baud)) {
    throw std::invalid_argument("base.baud = " + std::to_string(baud) + " is invalid");
  }
  if (!(max_v_mps > 0.0) || !(max_omega_rps > 0.0)) {
    throw std::invalid_argument("base.max_v_mps / max_omega_rps must be > 0");
  }
  if (sip_timeout_ms <= 0 || sync_attempts < 1) {
    throw std::invalid_argument("base.sip_timeout_ms = " + std::to_string(sip_timeout_ms) +
                                ", sync_attempts = " + std::to_string(sync_attempts) +
                                " are invalid (> 0)");
  }
}

P2osDriver::P2osDriver(const P2osDriverConfig& config, ClockFn clock)
    : config_((config.Validate(), config)), clock_(clock ? std::move(clock) : ClockFn(SteadyNowS)) {
  port_ = std::make_unique<SerialPort>(config_.device, config_.baud);
  if (Result<void> ok = Handshake(); !ok) {
    throw std::runtime_error("P3 base on " + config_.device + ": " + ok.error().message);
  }
}

P2osDriver::~P2osDriver() {
  // Leave the robot safe whatever ended the session (Ctrl-C included): zero speed, motors off,
  // connection closed.
  if (!port_ || !port_->is_open()) return;
  (void)Send(p2os::CommandPacket(p2os::kVel, 0));
  (void)Send(p2os::CommandPacket(p2os::kRVel, 0));
  (void)Send(p2os::CommandPacket(p2os::kEnable, 0));
  (void)Send(p2os::CommandPacket(p2os::kClose));
}

Result<void> P2osDriver::Send(const std::vector<std::uint8_t>& packet) {
  last_pulse_ = Clock::now();
  return port_->Write(packet);
}

Result<std::vector<std::uint8_t>> P2osDriver::WaitPacket(std::uint8_t first_byte,
                                                         milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  std::uint8_t buffer[256];
  for (;;) {
    if (StopRequested()) return Fail(Error::Code::kFailed, StopReason());
    while (auto payload = reader_.Next()) {
      if (!payload->empty() && (*payload)[0] == first_byte) return *payload;
    }
    const auto left = std::chrono::duration_cast<milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return Fail(Error::Code::kTimeout, "no reply");
    Result<std::size_t> n = port_->Read(buffer, sizeof(buffer), left);
    if (!n && n.error().code == Error::Code::kDevice) return tl::make_unexpected(n.error());
    if (n) reader_.Feed(buffer, *n);
  }
}

Result<void> P2osDriver::Handshake() {
  std::string failed = "SYNC0";
  for (int attempt = 0; attempt < config_.sync_attempts; ++attempt) {
    if (StopRequested()) return Fail(Error::Code::kFailed, StopReason());
    // A robot left connected by a crashed client: CLOSE puts it back to waiting for SYNC0.
    if (attempt > 0) (void)Send(p2os::CommandPacket(p2os::kClose));
    port_->DiscardInput();
    reader_.Clear();
    bool synced = true;
    for (std::uint8_t step : {p2os::kSync0, p2os::kSync1, p2os::kSync2}) {
      if (Result<void> sent = Send(p2os::CommandPacket(step)); !sent) return sent;
      Result<std::vector<std::uint8_t>> echo = WaitPacket(step, kHandshakeTimeout);
      if (!echo) {
        failed = "SYNC" + std::to_string(step);
        synced = false;
        break;
      }
      if (step == p2os::kSync2) {
        robot_.clear();
        for (std::size_t i = 1; i < echo->size(); ++i)
          robot_ += (*echo)[i] ? char((*echo)[i]) : ' ';
        while (!robot_.empty() && robot_.back() == ' ') robot_.pop_back();
      }
    }
    if (!synced) continue;
    if (Result<void> ok = Send(p2os::CommandPacket(p2os::kOpen)); !ok) return ok;
    if (Result<void> ok = Send(p2os::CommandPacket(p2os::kEnable, 1)); !ok) return ok;
    // The first SIP proves the connection is open.
    Result<bool> sip = Pump(Clock::now() + milliseconds(config_.sip_timeout_ms), true);
    if (sip && *sip) return {};
    failed = "OPEN (no SIP)";
  }
  return Fail(Error::Code::kTimeout, "no answer to " + failed + " after " +
                                         std::to_string(config_.sync_attempts) + " attempts");
}

void P2osDriver::Integrate(const p2os::Sip& sip) {
  // 15-bit positions wrap every 32.768 m: integrate the differences.
  if (last_sip_) {
    x_mm_ += Wrap15(int(sip.x_raw) - int(last_sip_->x_raw));
    y_mm_ += Wrap15(int(sip.y_raw) - int(last_sip_->y_raw));
  } else {
    x_mm_ = sip.x_raw >= 0x4000 ? int(sip.x_raw) - 0x8000 : sip.x_raw;
    y_mm_ = sip.y_raw >= 0x4000 ? int(sip.y_raw) - 0x8000 : sip.y_raw;
  }
  last_sip_ = sip;
  odometry_.stamp_s = clock_();
  odometry_.x_m = x_mm_ / 1000.0;
  odometry_.y_m = y_mm_ / 1000.0;
  odometry_.yaw_rad = sip.theta_raw * p2os::kAngleUnitRad;
  odometry_.v_mps = 0.5 * (sip.left_mmps + sip.right_mmps) / 1000.0;
  odometry_.omega_rps = sip.rotvel_ddps * kPi / 1800.0;
  odometry_.stalled = sip.stall_left || sip.stall_right;
}

Result<bool> P2osDriver::Pump(Clock::time_point deadline, bool stop_at_first_sip) {
  std::uint8_t buffer[512];
  bool got_sip = false;
  auto last_sip_time = Clock::now();
  for (;;) {
    if (StopRequested()) return tl::make_unexpected(StopError("P3 base on " + config_.device));
    while (auto payload = reader_.Next()) {
      if (Result<p2os::Sip> sip = p2os::DecodeSip(*payload); sip) {
        Integrate(*sip);
        got_sip = true;
        last_sip_time = Clock::now();
        if (stop_at_first_sip) return true;
      }
    }
    const auto now = Clock::now();
    if (now >= deadline) return got_sip;
    if (now - last_sip_time > milliseconds(config_.sip_timeout_ms)) {
      return Fail(Error::Code::kTimeout, "P3 base on " + config_.device + ": no SIP for " +
                                             std::to_string(config_.sip_timeout_ms) + " ms");
    }
    if (now - last_pulse_ > kPulsePeriod) {
      if (Result<void> ok = Send(p2os::CommandPacket(p2os::kPulse)); !ok) {
        return Fail(Error::Code::kDevice,
                    "P3 base on " + config_.device + ": " + ok.error().message);
      }
    }
    const auto wait =
        std::min(std::chrono::duration_cast<milliseconds>(deadline - now), milliseconds(50));
    Result<std::size_t> n = port_->Read(buffer, sizeof(buffer), std::max(wait, milliseconds(1)));
    if (!n && n.error().code == Error::Code::kDevice) {
      return Fail(Error::Code::kDevice, "P3 base on " + config_.device + ": " + n.error().message);
    }
    if (n) reader_.Feed(buffer, *n);
  }
}

Result<sensors::Odometry> P2osDriver::Drive(double v_mps, double omega_rps, double duration_s) {
  if (!std::isfinite(v_mps) || !std::isfinite(omega_rps) || !(duration_s >= 0.0)) {
    return Fail(Error::Code::kInvalidArgument, "Drive: non-finite command or negative duration");
  }
  const double v = std::clamp(v_mps, -config_.max_v_mps, config_.max_v_mps);
  const double w = std::clamp(omega_rps, -config_.max_omega_rps, config_.max_omega_rps);
  for (const auto& packet : {p2os::CommandPacket(p2os::kVel, int(std::lround(v * 1000.0))),
                             p2os::CommandPacket(p2os::kRVel, int(std::lround(w * 180.0 / kPi)))}) {
    if (Result<void> ok = Send(packet); !ok) {
      return Fail(Error::Code::kDevice, "P3 base on " + config_.device + ": " + ok.error().message);
    }
  }
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(duration_s));
  Result<bool> pumped = Pump(deadline, false);
  if (!pumped) return tl::make_unexpected(pumped.error());
  if (!*pumped) return ReadOdometry();
  return odometry_;
}

Result<sensors::Odometry> P2osDriver::ReadOdometry() {
  // Whatever SIPs are buffered, then at least one fresh one.
  Result<bool> drained = Pump(Clock::now(), false);
  if (!drained) return tl::make_unexpected(drained.error());
  Result<bool> fresh = Pump(Clock::now() + milliseconds(config_.sip_timeout_ms), true);
  if (!fresh) return tl::make_unexpected(fresh.error());
  if (!*fresh) {
    return Fail(Error::Code::kTimeout, "P3 base on " + config_.device + ": no SIP for " +
                                           std::to_string(config_.sip_timeout_ms) + " ms");
  }
  return odometry_;
}

}  // namespace pitchlab::hw
