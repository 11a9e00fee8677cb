#include "pitchlab/hw/p2os_driver.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "pitchlab/hw/stop_request.hpp"

namespace pitchlab::hw {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;
constexpr double kPi = 3.14159265358979323846;
constexpr milliseconds kHandshakeTimeout{500};
// PULSE at least every second whatever the mission does: half the P3's 2 s watchdog (ARCOS
// stops the motors after that long without a packet).
constexpr milliseconds kPulsePeriod{500};
constexpr milliseconds kServiceRead{50};  // the service thread's read slice: SIPs come at 10 Hz

double SteadyNowS() {
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

// Difference of two 15-bit wrapping positions, in (-2^14, 2^14].
int Wrap15(int delta) {
  delta &= 0x7FFF;
  return delta > 0x4000 ? delta - 0x8000 : delta;
}

// A 15-bit position as signed (the first SIP after power-on may sit just below the origin).
int Signed15(int raw) { return raw >= 0x4000 ? raw - 0x8000 : raw; }

bool IsSync(std::uint8_t first) { return first <= p2os::kSync2; }
bool IsSip(std::uint8_t first) { return first == p2os::kSipStopped || first == p2os::kSipMoving; }

// NUL-terminated strings after the SYNC2 command byte: name, class, subclass.
std::vector<std::string> Sync2Strings(const std::vector<std::uint8_t>& payload) {
  std::vector<std::string> out(1);
  for (std::size_t i = 1; i < payload.size(); ++i) {
    if (payload[i] == 0) {
      out.emplace_back();
    } else {
      out.back() += char(payload[i]);
    }
  }
  if (out.back().empty()) out.pop_back();
  return out;
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
  running_ = true;
  service_ = std::thread([this] { Service(); });
}

P2osDriver::~P2osDriver() {
  running_ = false;
  if (service_.joinable()) service_.join();
  // Leave the robot safe whatever ended the session (Ctrl-C included): zero speed, motors off,
  // connection closed.
  if (!port_ || !port_->is_open()) return;
  (void)Send(p2os::CommandPacket(p2os::kVel, 0));
  (void)Send(p2os::CommandPacket(p2os::kRVel, 0));
  (void)Send(p2os::CommandPacket(p2os::kEnable, 0));
  (void)Send(p2os::CommandPacket(p2os::kClose));
}

Result<void> P2osDriver::Send(const std::vector<std::uint8_t>& packet) {
  std::lock_guard<std::mutex> lock(write_mutex_);
  last_sent_ = Clock::now();
  return port_->Write(packet);
}

Result<std::vector<std::uint8_t>> P2osDriver::WaitPacket(bool (*wanted)(std::uint8_t),
                                                         milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  std::uint8_t buffer[256];
  for (;;) {
    if (StopRequested()) return Fail(Error::Code::kFailed, StopReason());
    while (auto payload = reader_.Next()) {
      if (!payload->empty() && wanted((*payload)[0])) return *payload;
    }
    const auto left = std::chrono::duration_cast<milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return Fail(Error::Code::kTimeout, "no reply");
    Result<std::size_t> n = port_->Read(buffer, sizeof(buffer), left);
    if (!n && n.error().code == Error::Code::kDevice) return tl::make_unexpected(n.error());
    if (n) reader_.Feed(buffer, *n);
  }
}

Result<void> P2osDriver::SyncOnce() {
  for (std::uint8_t step : {p2os::kSync0, p2os::kSync1, p2os::kSync2}) {
    if (Result<void> sent = Send(p2os::CommandPacket(step)); !sent) return sent;
    Result<std::vector<std::uint8_t>> echo = WaitPacket(IsSync, kHandshakeTimeout);
    if (!echo || (*echo)[0] != step) {
      return Fail(Error::Code::kTimeout, "SYNC" + std::to_string(step));
    }
    if (step != p2os::kSync2) continue;
    const std::vector<std::string> names = Sync2Strings(*echo);
    robot_.clear();
    for (const std::string& n : names) robot_ += (robot_.empty() ? "" : " ") + n;
    // The subclass decides the SIP's units: an unknown one would be read wrongly.
    Result<PioneerParams> params = FindPioneerParams(names.size() >= 3 ? names[2] : std::string());
    if (!params) return Fail(Error::Code::kInvalidArgument, params.error().message);
    params_ = *params;
  }
  return {};
}

Result<void> P2osDriver::Handshake() {
  std::string failed = "SYNC0";
  for (int attempt = 0; attempt < config_.sync_attempts; ++attempt) {
    if (StopRequested()) return Fail(Error::Code::kFailed, StopReason());
    // A robot left connected by a crashed client: CLOSE puts it back to waiting for SYNC0.
    if (attempt > 0) (void)Send(p2os::CommandPacket(p2os::kClose));
    port_->DiscardInput();
    reader_.Clear();
    if (Result<void> synced = SyncOnce(); !synced) {
      if (synced.error().code != Error::Code::kTimeout) return synced;
      failed = synced.error().message;
      continue;
    }
    if (Result<void> ok = Send(p2os::CommandPacket(p2os::kOpen)); !ok) return ok;
    if (Result<void> ok = Send(p2os::CommandPacket(p2os::kEnable, 1)); !ok) return ok;
    // The first SIP proves the connection is open.
    Result<std::vector<std::uint8_t>> first =
        WaitPacket(IsSip, milliseconds(config_.sip_timeout_ms));
    if (first) {
      if (Result<p2os::Sip> sip = p2os::DecodeSip(*first); sip) {
        std::lock_guard<std::mutex> lock(mutex_);
        Integrate(*sip);
        return {};
      }
    }
    failed = "OPEN (no SIP)";
  }
  return Fail(Error::Code::kTimeout, "no answer to " + failed + " after " +
                                         std::to_string(config_.sync_attempts) + " attempts");
}

void P2osDriver::Integrate(const p2os::Sip& sip) {
  // Robot units to mm, rad and mm/s by the subclass's factors. 15-bit positions wrap every
  // 32768 units: integrate the differences.
  const double dist = params_.dist_conv_mm;
  if (last_sip_) {
    x_mm_ += Wrap15(int(sip.x_raw) - int(last_sip_->x_raw)) * dist;
    y_mm_ += Wrap15(int(sip.y_raw) - int(last_sip_->y_raw)) * dist;
  } else {
    x_mm_ = Signed15(sip.x_raw) * dist;
    y_mm_ = Signed15(sip.y_raw) * dist;
  }
  last_sip_ = sip;
  ++sips_;
  last_sip_time_ = Clock::now();
  odometry_.stamp_s = clock_();
  odometry_.x_m = x_mm_ / 1000.0;
  odometry_.y_m = y_mm_ / 1000.0;
  odometry_.yaw_rad = std::remainder(sip.theta_raw * params_.angle_conv_rad, 2.0 * kPi);
  odometry_.v_mps = 0.5 * (sip.left_mmps + sip.right_mmps) * params_.vel_conv_mmps / 1000.0;
  odometry_.omega_rps = sip.rotvel_ddps * kPi / 1800.0;
  odometry_.stalled = sip.stall_left || sip.stall_right;
}

void P2osDriver::Service() {
  std::uint8_t buffer[512];
  const auto fail = [this](const Error& e) {
    std::lock_guard<std::mutex> lock(mutex_);
    error_ = Error{Error::Code::kDevice, "P3 base on " + config_.device + ": " + e.message};
    sip_arrived_.notify_all();
  };
  while (running_) {
    bool pulse_due = false;
    {
      std::lock_guard<std::mutex> lock(write_mutex_);
      pulse_due = Clock::now() - last_sent_ >= kPulsePeriod;
    }
    if (pulse_due) {
      if (Result<void> ok = Send(p2os::CommandPacket(p2os::kPulse)); !ok) return fail(ok.error());
    }
    Result<std::size_t> n = port_->Read(buffer, sizeof(buffer), kServiceRead);
    if (!n && n.error().code == Error::Code::kDevice) return fail(n.error());
    if (!n) continue;
    reader_.Feed(buffer, *n);
    std::lock_guard<std::mutex> lock(mutex_);
    while (auto payload = reader_.Next()) {
      if (Result<p2os::Sip> sip = p2os::DecodeSip(*payload); sip) Integrate(*sip);
    }
    checksum_errors_ = reader_.checksum_errors();
    sip_arrived_.notify_all();
  }
}

Result<void> P2osDriver::Wait(Clock::time_point deadline, std::uint64_t after, bool need_sip) {
  const milliseconds silence(config_.sip_timeout_ms);
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    if (error_) return tl::make_unexpected(*error_);
    if (StopRequested()) return tl::make_unexpected(StopError("P3 base on " + config_.device));
    if (need_sip && sips_ > after) return {};
    const auto now = Clock::now();
    if (now - last_sip_time_ > silence || (need_sip && now >= deadline)) {
      return Fail(Error::Code::kTimeout, "P3 base on " + config_.device + ": no SIP for " +
                                             std::to_string(config_.sip_timeout_ms) + " ms");
    }
    if (!need_sip && now >= deadline) return {};
    // Wake for the next SIP, the deadline, or in time to see a silent robot or a stop request.
    sip_arrived_.wait_until(lock, std::min(deadline, now + kServiceRead));
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
  std::uint64_t at_start = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    at_start = sips_;
  }
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(duration_s));
  if (Result<void> waited = Wait(deadline, at_start, false); !waited) {
    return tl::make_unexpected(waited.error());
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (sips_ > at_start) return odometry_;
  }
  return ReadOdometry();
}

Result<sensors::Odometry> P2osDriver::ReadOdometry() {
  std::uint64_t after = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    after = sips_;
  }
  const auto deadline = Clock::now() + milliseconds(config_.sip_timeout_ms);
  if (Result<void> waited = Wait(deadline, after, true); !waited) {
    return tl::make_unexpected(waited.error());
  }
  std::lock_guard<std::mutex> lock(mutex_);
  return odometry_;
}

}  // namespace pitchlab::hw
