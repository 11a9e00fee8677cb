#include "pitchlab/hw/p2os_emulator.hpp"

#include <chrono>
#include <cmath>

namespace pitchlab::hw {
namespace {

constexpr double kPi = 3.14159265358979323846;

double NowS() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::int16_t WrapAngleUnits(double yaw_rad) {
  const double wrapped = std::remainder(yaw_rad, 2.0 * kPi);
  return std::int16_t(std::lround(wrapped / p2os::kAngleUnitRad));
}

}  // namespace

P2osEmulator::P2osEmulator(const P2osEmulatorConfig& config, BasePhysics physics,
                           std::string link_path)
    : EmulatedDevice("p3", config.baud, std::move(link_path)),
      config_(config),
      physics_(std::move(physics)) {
  last_step_s_ = NowS();
  Start();
}

P2osEmulator::~P2osEmulator() { Stop(); }

void P2osEmulator::OnPowerOn() {
  sync_stage_ = 0;
  connected_ = enabled_ = false;
  Command(0.0, 0.0);
  reader_.Clear();
}

BaseState P2osEmulator::State() { return physics_.state ? physics_.state() : own_; }

void P2osEmulator::Command(double v_mps, double omega_rps) {
  v_mps_ = v_mps;
  omega_rps_ = omega_rps;
  if (physics_.command) physics_.command(v_mps, omega_rps);
}

void P2osEmulator::OnBytes(const std::uint8_t* bytes, std::size_t size) {
  if (!DriverBaudMatches()) {
    CountRequest(false);
    return;
  }
  reader_.Feed(bytes, size);
  while (auto payload = reader_.Next()) {
    if (payload->empty()) continue;
    CountRequest(true);
    last_packet_s_ = NowS();
    Handle(*payload);
  }
}

void P2osEmulator::Handle(const std::vector<std::uint8_t>& p) {
  const std::uint8_t command = p[0];
  if (!connected_) {
    // The handshake: SYNC0, SYNC1, SYNC2 in order, each echoed; out of order restarts it.
    if (command <= p2os::kSync2 && p.size() == 1 && command == sync_stage_) {
      if (command == p2os::kSync2) {
        Send(p2os::Sync2Reply(config_.name, config_.type, config_.subtype));
      } else {
        Send(p2os::CommandPacket(command));
      }
      sync_stage_ = command + 1;
      return;
    }
    if (command == p2os::kOpen && sync_stage_ == 3) {
      connected_ = true;
      next_sip_s_ = NowS();
      return;
    }
    if (command == p2os::kSync0 && p.size() == 1) {
      sync_stage_ = 1;
      Send(p2os::CommandPacket(p2os::kSync0));
    }
    return;
  }
  Result<int> argument = p2os::CommandArgument(p);
  switch (command) {
    case p2os::kPulse:
      break;
    case p2os::kClose:
      Command(0.0, 0.0);
      connected_ = enabled_ = false;
      sync_stage_ = 0;
      break;
    case p2os::kEnable:
      if (argument) enabled_ = *argument != 0;
      if (!enabled_) Command(0.0, 0.0);
      break;
    case p2os::kVel:
      if (argument && enabled_) Command(*argument / 1000.0, omega_rps_);
      break;
    case p2os::kRVel:
      if (argument && enabled_) Command(v_mps_, *argument * kPi / 180.0);
      break;
    case p2os::kVel2:
      // Two signed bytes in the argument word; a client packing them into a short may send a
      // "negative" word (ARGNINT), so the word is taken modulo 2^16.
      if (argument && enabled_) {
        const std::uint16_t word = std::uint16_t(*argument);
        const double left = std::int8_t(word >> 8) * p2os::kVel2UnitMmps / 1000.0;
        const double right = std::int8_t(word & 0xFF) * p2os::kVel2UnitMmps / 1000.0;
        Command(0.5 * (left + right), (right - left) / config_.track_m);
      }
      break;
    case p2os::kStop:
    case p2os::kEStop:
      Command(0.0, 0.0);
      break;
    case p2os::kSetO:
      origin_ = State();
      break;
    default:
      break;  // unknown commands are ignored, as ARCOS does
  }
}

void P2osEmulator::OnIdle() {
  const double now = NowS();
  if (!physics_.state) {
    // Built-in unicycle: integrate the command.
    const double dt = now - last_step_s_;
    own_.yaw_rad += omega_rps_ * dt;
    own_.x_m += v_mps_ * std::cos(own_.yaw_rad) * dt;
    own_.y_m += v_mps_ * std::sin(own_.yaw_rad) * dt;
    own_.left_mps = v_mps_ - 0.5 * config_.track_m * omega_rps_;
    own_.right_mps = v_mps_ + 0.5 * config_.track_m * omega_rps_;
    own_.omega_rps = omega_rps_;
  }
  last_step_s_ = now;
  if (!connected_ || !plugged()) return;
  if ((v_mps_ != 0.0 || omega_rps_ != 0.0) && now - last_packet_s_ > config_.watchdog_s) {
    Command(0.0, 0.0);  // watchdog: the client went quiet
  }
  if (now < next_sip_s_) return;
  next_sip_s_ += config_.sip_period_s;
  if (next_sip_s_ < now) next_sip_s_ = now + config_.sip_period_s;
  const BaseState s = State();
  // Odometry relative to the last SETO, in the robot's wrapping 15-bit millimetres.
  const double c = std::cos(-origin_.yaw_rad), sn = std::sin(-origin_.yaw_rad);
  const double dx = s.x_m - origin_.x_m, dy = s.y_m - origin_.y_m;
  p2os::Sip sip;
  sip.moving = std::abs(s.left_mps) + std::abs(s.right_mps) > 1e-3;
  sip.x_raw = std::uint16_t(std::lround(1000.0 * (c * dx - sn * dy)) & 0x7FFF);
  sip.y_raw = std::uint16_t(std::lround(1000.0 * (sn * dx + c * dy)) & 0x7FFF);
  sip.theta_raw = WrapAngleUnits(s.yaw_rad - origin_.yaw_rad);
  sip.left_mmps = std::int16_t(std::lround(1000.0 * s.left_mps));
  sip.right_mmps = std::int16_t(std::lround(1000.0 * s.right_mps));
  sip.battery_dv = std::uint8_t(std::lround(10.0 * s.battery_v));
  sip.stall_left = s.stall_left;
  sip.stall_right = s.stall_right;
  sip.flags = enabled_ ? 1 : 0;
  sip.rotvel_ddps = std::int16_t(std::lround(s.omega_rps * 1800.0 / kPi));
  Send(p2os::Encode(p2os::EncodeSip(sip)));
}

}  // namespace pitchlab::hw
