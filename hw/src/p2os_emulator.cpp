#include "pitchlab/hw/p2os_emulator.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

namespace pitchlab::hw {
namespace {

constexpr double kPi = 3.14159265358979323846;

double NowS() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

PioneerParams ParamsOf(const std::string& subtype) {
  Result<PioneerParams> params = FindPioneerParams(subtype);
  if (!params) throw std::invalid_argument("P2OS emulator: " + params.error().message);
  return *params;
}

}  // namespace

P2osEmulator::P2osEmulator(const P2osEmulatorConfig& config, BasePhysics physics,
                           std::string link_path)
    : EmulatedDevice("p3", config.baud, std::move(link_path)),
      config_(config),
      params_(ParamsOf(config.subtype)),
      physics_(std::move(physics)) {
  last_step_s_ = NowS();
  last_ = State();
  Start();
}

P2osEmulator::~P2osEmulator() { Stop(); }

double P2osEmulator::seconds_since_client_packet() const { return NowS() - last_packet_s_; }

void P2osEmulator::OnPowerOn() {
  sync_stage_ = 0;
  connected_ = enabled_ = false;
  watchdog_stopped_ = false;
  Command(0.0, 0.0);
  reader_.Clear();
  x_m_ = y_m_ = yaw_rad_ = 0.0;
  last_ = State();
}

BaseState P2osEmulator::State() { return physics_.state ? physics_.state() : own_; }

void P2osEmulator::Command(double v_mps, double omega_rps) {
  v_mps_ = v_mps;
  omega_rps_ = omega_rps;
  Drive();
}

void P2osEmulator::Drive() {
  const auto [v, omega] = command();
  if (physics_.command) physics_.command(v, omega);
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
    // "The robot will automatically resume activity, including motion, as soon as
    // communications are restored" (Pioneer 3 Operations Manual, Safety Watchdogs): ROS p2os
    // sends a velocity only when it changes, so a robot that stayed stopped would not move again.
    if (watchdog_stopped_.exchange(false)) Drive();
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
  // Two bytes in one argument word (VEL2, aux power); a client packing them into a short may
  // send a "negative" word (ARGNINT), so the word is taken modulo 2^16.
  const std::uint16_t word = argument ? std::uint16_t(*argument) : 0;
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
      // Left in bits 8-15, right in 0-7, signed, Vel2Divisor mm/s each; (v, omega) through the
      // track the physics turns with, so the wheels run at the commanded speeds.
      if (argument && enabled_) {
        const double left = std::int8_t(word >> 8) * params_.vel2_divisor_mmps / 1000.0;
        const double right = std::int8_t(word & 0xFF) * params_.vel2_divisor_mmps / 1000.0;
        const double track = physics_.track_m > 0.0 ? physics_.track_m : config_.track_m;
        Command(0.5 * (left + right), (right - left) / track);
      }
      break;
    case p2os::kAuxPower:
      if (argument && physics_.aux_power) physics_.aux_power(word >> 8, (word & 0xFF) != 0);
      break;
    case p2os::kStop:
      Command(0.0, 0.0);
      break;
    case p2os::kEStop:  // "emergency stop, overrides decel" (ARIA's ArCommands)
      v_mps_ = omega_rps_ = 0.0;
      if (physics_.emergency_stop) {
        physics_.emergency_stop();
      } else {
        Drive();
      }
      break;
    case p2os::kSetO:
      x_m_ = y_m_ = yaw_rad_ = 0.0;
      break;
    default:
      break;  // unknown commands are ignored, as ARCOS does
  }
}

void P2osEmulator::StepBuiltIn(double now_s) {
  // Built-in unicycle: integrate the command in force.
  const double dt = now_s - last_step_s_;
  const auto [v_mps, omega_rps] = command();
  own_.yaw_rad += omega_rps * dt;
  own_.x_m += v_mps * std::cos(own_.yaw_rad) * dt;
  own_.y_m += v_mps * std::sin(own_.yaw_rad) * dt;
  own_.left_mps = v_mps - 0.5 * config_.track_m * omega_rps;
  own_.right_mps = v_mps + 0.5 * config_.track_m * omega_rps;
  own_.omega_rps = omega_rps;
  own_.left_travel_m += own_.left_mps * dt;
  own_.right_travel_m += own_.right_mps * dt;
}

void P2osEmulator::OnIdle() {
  const double now = NowS();
  if (!physics_.state) StepBuiltIn(now);
  last_step_s_ = now;
  if (!connected_ || !plugged()) return;
  if (!watchdog_stopped_ && (v_mps_ != 0.0 || omega_rps_ != 0.0) &&
      now - last_packet_s_ > config_.watchdog_s) {
    watchdog_stopped_ = true;  // the client went quiet: motors stop until it speaks again
    Drive();
  }
  if (now < next_sip_s_) return;
  next_sip_s_ += config_.sip_period_s;
  if (next_sip_s_ < now) next_sip_s_ = now + config_.sip_period_s;
  SendSip();
}

bool P2osEmulator::Parked(const BaseState& s) {
  // A P3 commanded to zero whose wheels have stopped turning holds them: the encoders count
  // nothing, so the odometry stands still. Whatever the physics adds there (a gyro's drift,
  // a position loop's +-1 mm/s) is below one encoder tick and not reported; wheels pushed a
  // tick or more count again.
  const double tick =
      physics_.encoder_tick_m > 0.0 ? physics_.encoder_tick_m : params_.dist_conv_mm / 1000.0;
  if (v_mps_ != 0.0 || omega_rps_ != 0.0) {
    holding_ = false;
  } else if (!holding_) {
    if (std::abs(s.left_travel_m - last_.left_travel_m) < tick &&
        std::abs(s.right_travel_m - last_.right_travel_m) < tick) {
      holding_ = true;
      hold_left_m_ = s.left_travel_m;
      hold_right_m_ = s.right_travel_m;
    }
  } else if (std::abs(s.left_travel_m - hold_left_m_) >= tick ||
             std::abs(s.right_travel_m - hold_right_m_) >= tick) {
    holding_ = false;
  }
  return holding_;
}

void P2osEmulator::SendSip() {
  const BaseState s = State();
  const bool parked = Parked(s);
  if (!parked) {
    // The physics' motion since the last SIP, in the robot frame, onto the reported pose.
    const double c = std::cos(last_.yaw_rad), sn = std::sin(last_.yaw_rad);
    const double dx = s.x_m - last_.x_m, dy = s.y_m - last_.y_m;
    const double forward = c * dx + sn * dy, left = -sn * dx + c * dy;
    x_m_ += std::cos(yaw_rad_) * forward - std::sin(yaw_rad_) * left;
    y_m_ += std::sin(yaw_rad_) * forward + std::cos(yaw_rad_) * left;
    yaw_rad_ =
        std::remainder(yaw_rad_ + std::remainder(s.yaw_rad - last_.yaw_rad, 2.0 * kPi), 2.0 * kPi);
  }
  last_ = s;
  // Positions in wrapping 15-bit robot units (DistConvFactor mm), heading in AngleConvFactor
  // units, wheel speeds in VelConvFactor mm/s.
  p2os::Sip sip;
  sip.x_raw = std::uint16_t(std::lround(1000.0 * x_m_ / params_.dist_conv_mm) & 0x7FFF);
  sip.y_raw = std::uint16_t(std::lround(1000.0 * y_m_ / params_.dist_conv_mm) & 0x7FFF);
  sip.theta_raw = std::int16_t(std::lround(yaw_rad_ / params_.angle_conv_rad));
  if (!parked) {
    sip.left_mmps = std::int16_t(std::lround(1000.0 * s.left_mps / params_.vel_conv_mmps));
    sip.right_mmps = std::int16_t(std::lround(1000.0 * s.right_mps / params_.vel_conv_mmps));
    sip.rotvel_ddps = std::int16_t(std::lround(s.omega_rps * 1800.0 / kPi));
  }
  sip.moving = sip.left_mmps != 0 || sip.right_mmps != 0;
  sip.battery_dv = std::uint8_t(std::lround(10.0 * s.battery_v));
  sip.stall_left = s.stall_left;
  sip.stall_right = s.stall_right;
  sip.flags = enabled_ ? 1 : 0;
  Send(p2os::Encode(p2os::EncodeSip(sip)));
}

}  // namespace pitchlab::hw
