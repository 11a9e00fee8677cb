#include "pitchlab/hw/lms200_driver.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <thread>
#include <vector>

#include "pitchlab/hw/stop_request.hpp"

namespace pitchlab::hw {
namespace {

using Clock = std::chrono::steady_clock;
using lms200::Telegram;
using std::chrono::milliseconds;

constexpr milliseconds kConfigureTimeout{3000};  // EEPROM write
constexpr milliseconds kReconnectPause{300};
constexpr double kLineMargin_s = 0.2;  // beyond the nominal line period before retrying

std::string Hex(unsigned v) {
  static const char* digits = "0123456789ABCDEF";
  return std::string("0x") + digits[(v >> 4) & 0xF] + digits[v & 0xF];
}

milliseconds Remaining(Clock::time_point deadline) {
  return std::max(milliseconds(0),
                  std::chrono::duration_cast<milliseconds>(deadline - Clock::now()));
}

double SteadyNowS() {
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

}  // namespace

void Lms200DriverConfig::Validate() const {
  if (device.empty()) throw std::invalid_argument("lms200.device is empty");
  lms.Validate();
  if (reply_timeout_ms <= 0) {
    throw std::invalid_argument("lms200.reply_timeout_ms = " + std::to_string(reply_timeout_ms) +
                                " is invalid (> 0)");
  }
  if (retries < 1) {
    throw std::invalid_argument("lms200.retries = " + std::to_string(retries) +
                                " is invalid (>= 1)");
  }
  if (reconnects < 0) {
    throw std::invalid_argument("lms200.reconnects = " + std::to_string(reconnects) +
                                " is invalid (>= 0)");
  }
}

Lms200Driver::Lms200Driver(const Lms200DriverConfig& config, ClockFn clock)
    : config_(config),
      clock_(clock ? std::move(clock) : ClockFn(SteadyNowS)),
      model_((config.Validate(), config.lms)) {
  port_ = std::make_unique<SerialPort>(config_.device, 9600);
  if (Result<void> ready = Initialize(); !ready) {
    throw std::runtime_error("LMS200 on " + config_.device + ": " + ready.error().message);
  }
}

Lms200Driver::~Lms200Driver() {
  // Leave the device quiet: a streaming LMS would flood the next user's port.
  if (config_.continuous && port_ && port_->is_open()) {
    (void)port_->Write(lms200::Encode(lms200::SwitchModeRequest(lms200::kModeOnRequest)));
  }
}

const Lms200DriverStats& Lms200Driver::stats() const {
  stats_.reader = reader_.stats();
  return stats_;
}

Result<Telegram> Lms200Driver::WaitFor(std::uint8_t reply_command, bool need_ack,
                                       Clock::time_point deadline) {
  bool acked = !need_ack;
  std::uint8_t buffer[1024];
  for (;;) {
    if (StopRequested()) return Fail(Error::Code::kFailed, StopReason());
    while (auto event = reader_.Next()) {
      using Kind = lms200::ReaderEvent::Kind;
      if (event->kind == Kind::kAck) acked = true;
      if (event->kind == Kind::kNak && !acked) {
        return Fail(Error::Code::kProtocol, "device answered NAK");
      }
      // A reply whose ACK was lost still counts; other telegrams (power-on, stale) are skipped.
      if (event->kind == Kind::kTelegram && event->telegram.command == reply_command) {
        return std::move(event->telegram);
      }
    }
    const milliseconds left = Remaining(deadline);
    if (left.count() == 0) {
      return Fail(Error::Code::kTimeout, std::string(acked ? "no reply " : "no ACK ") +
                                             Hex(reply_command) + " within the timeout");
    }
    Result<std::size_t> n = port_->Read(buffer, sizeof(buffer), left);
    if (!n && n.error().code == Error::Code::kTimeout) continue;
    if (!n) return Fail(n.error().code, n.error().message);
    reader_.Feed(buffer, *n);
  }
}

Result<Telegram> Lms200Driver::Transact(const Telegram& request, milliseconds timeout,
                                        int attempts) {
  if (attempts <= 0) attempts = config_.retries;
  Error last{Error::Code::kTimeout, "not sent"};
  for (int attempt = 0; attempt < attempts; ++attempt) {
    if (attempt > 0) ++stats_.retries;
    port_->DiscardInput();
    reader_.Clear();
    if (Result<void> sent = port_->Write(lms200::Encode(request)); !sent)
      return Fail(sent.error().code, sent.error().message);
    Result<Telegram> reply =
        WaitFor(std::uint8_t(request.command | lms200::kReplyBit), true, Clock::now() + timeout);
    if (reply) return reply;
    if (reply.error().code == Error::Code::kDevice || StopRequested()) return reply;
    last = reply.error();
  }
  return Fail(last.code, "request " + Hex(request.command) + " failed after " +
                             std::to_string(attempts) + " attempts: " + last.message);
}

Result<int> Lms200Driver::ProbeBaud() {
  // After power-on the LMS talks 9600; after a warm restart of the host it may still be at the
  // last rate. Ask "values on request" at each rate until one answers.
  std::vector<int> rates = {9600, config_.lms.baud, 38400, 19200, 500000};
  std::vector<int> tried;
  for (int baud : rates) {
    if (std::find(tried.begin(), tried.end(), baud) != tried.end()) continue;
    tried.push_back(baud);
    if (!port_->SetBaud(baud)) continue;  // e.g. 500000 on a pty
    Result<Telegram> reply = Transact(lms200::SwitchModeRequest(lms200::kModeOnRequest),
                                      milliseconds(config_.reply_timeout_ms), 2);
    if (reply) return baud;
    if (reply.error().code == Error::Code::kDevice || StopRequested())
      return Fail(reply.error().code, reply.error().message);
  }
  return Fail(Error::Code::kTimeout, "no answer at 9600, 19200, 38400 or 500000 baud");
}

Result<void> Lms200Driver::SwitchBaud(int baud) {
  const auto code = lms200::BaudModeCode(baud);
  if (!code)
    return Fail(Error::Code::kInvalidArgument, "the LMS200 cannot do baud " + std::to_string(baud));
  // Acknowledged at the old rate; the device then switches, and so do we.
  Result<Telegram> reply =
      Transact(lms200::SwitchModeRequest(*code), milliseconds(config_.reply_timeout_ms));
  if (!reply) return Fail(reply.error().code, "baud switch: " + reply.error().message);
  if (reply->data.empty() || reply->data[0] != 0x00) {
    return Fail(Error::Code::kDevice, "baud switch to " + std::to_string(baud) + " refused");
  }
  if (Result<void> set = port_->SetBaud(baud); !set) return set;
  Result<Telegram> check = Transact(lms200::SwitchModeRequest(lms200::kModeOnRequest),
                                    milliseconds(config_.reply_timeout_ms));
  if (!check)
    return Fail(check.error().code, "no answer after switching to " + std::to_string(baud) +
                                        " baud: " + check.error().message);
  return {};
}

Result<void> Lms200Driver::SetVariant() {
  const int fov = int(std::lround(config_.lms.fov_deg));
  const int res = int(std::lround(config_.lms.resolution_deg * 100.0));
  Result<Telegram> reply =
      Transact(lms200::VariantRequest(fov, res), milliseconds(config_.reply_timeout_ms));
  if (!reply) return Fail(reply.error().code, "variant: " + reply.error().message);
  const auto& d = reply->data;
  if (d.size() < 5 || d[0] != 0x01 || (d[1] | (d[2] << 8)) != fov || (d[3] | (d[4] << 8)) != res) {
    return Fail(Error::Code::kDevice, "variant " + std::to_string(fov) + " deg / " +
                                          std::to_string(res / 100.0) + " deg refused");
  }
  return {};
}

Result<void> Lms200Driver::SetRangeMode() {
  const std::uint8_t wanted = config_.lms.range_mode == sensors::Lms200RangeMode::kMm ? 1 : 0;
  Result<Telegram> current =
      Transact(lms200::ConfigRequest(), milliseconds(config_.reply_timeout_ms));
  if (!current)
    return Fail(current.error().code, "reading the configuration: " + current.error().message);
  std::vector<std::uint8_t> block = current->data;
  if (!block.empty()) block.pop_back();  // status byte
  if (block.size() <= lms200::kConfigUnitsIndex) {
    return Fail(Error::Code::kProtocol,
                "configuration block of " + std::to_string(block.size()) + " bytes");
  }
  if (block[lms200::kConfigUnitsIndex] == wanted) return {};
  Result<Telegram> setup =
      Transact(lms200::SetupModeRequest(), milliseconds(config_.reply_timeout_ms));
  if (!setup || setup->data.empty() || setup->data[0] != 0x00) {
    return Fail(Error::Code::kDevice, "installation mode refused (password)");
  }
  block[lms200::kConfigUnitsIndex] = wanted;
  Result<Telegram> written = Transact(lms200::ConfigureRequest(block), kConfigureTimeout);
  if (!written || written->data.empty() || written->data[0] != 0x01) {
    return Fail(Error::Code::kDevice,
                std::string("range mode ") + (wanted ? "mm" : "cm") + " refused");
  }
  return {};
}

Result<void> Lms200Driver::Initialize() {
  reader_.Clear();
  Result<int> baud = ProbeBaud();
  if (!baud) return Fail(baud.error().code, baud.error().message);
  if (*baud != config_.lms.baud) {
    if (Result<void> switched = SwitchBaud(config_.lms.baud); !switched) return switched;
  }
  Result<Telegram> type = Transact(lms200::TypeRequest(), milliseconds(config_.reply_timeout_ms));
  if (!type) return Fail(type.error().code, "type request: " + type.error().message);
  type_.assign(type->data.begin(), type->data.end() - (type->data.empty() ? 0 : 1));
  if (Result<void> variant = SetVariant(); !variant) return variant;
  if (Result<void> mode = SetRangeMode(); !mode) return mode;
  const std::uint8_t output = config_.continuous ? lms200::kModeContinuous : lms200::kModeOnRequest;
  Result<Telegram> started =
      Transact(lms200::SwitchModeRequest(output), milliseconds(config_.reply_timeout_ms));
  if (!started) return Fail(started.error().code, "output mode: " + started.error().message);
  return {};
}

Result<void> Lms200Driver::Reconnect() {
  Error last{Error::Code::kDevice, "no reconnect attempted"};
  for (int i = 0; i < config_.reconnects && !StopRequested(); ++i) {
    std::this_thread::sleep_for(kReconnectPause);
    if (Result<void> opened = port_->Reopen(); !opened) {
      last = opened.error();
      continue;
    }
    if (Result<void> ready = Initialize(); !ready) {
      last = ready.error();
      continue;
    }
    ++stats_.reconnects;
    return {};
  }
  port_->Close();
  return Fail(Error::Code::kDevice, "device lost and not back after " +
                                        std::to_string(config_.reconnects) +
                                        " reconnects: " + last.message);
}

Result<sensors::LaserLine> Lms200Driver::ToLine(const Telegram& reply, double stamp_s) {
  Result<lms200::MeasuredValues> mv = lms200::DecodeMeasuredValues(reply);
  if (!mv) return Fail(mv.error().code, mv.error().message);
  const lms200::Units want = config_.lms.range_mode == sensors::Lms200RangeMode::kMm
                                 ? lms200::Units::kMm
                                 : lms200::Units::kCm;
  if (mv->units != want) return Fail(Error::Code::kProtocol, "measured values in the wrong unit");
  if (int(mv->values.size()) != model_.readings()) {
    return Fail(Error::Code::kProtocol, std::to_string(mv->values.size()) + " readings, expected " +
                                            std::to_string(model_.readings()));
  }
  if ((mv->status & 0x07) != 0) {
    return Fail(Error::Code::kDevice, "device status " + Hex(mv->status) + " reports a fault");
  }
  sensors::LaserLine line;
  line.stamp_s = stamp_s;
  line.duration_s = model_.measurement_time_s();
  line.angle_min_rad = model_.angle_min_rad();
  line.angle_increment_rad = model_.angle_increment_rad();
  line.ranges_m.resize(mv->values.size());
  line.status.resize(mv->values.size());
  for (std::size_t i = 0; i < mv->values.size(); ++i) {
    std::tie(line.ranges_m[i], line.status[i]) = lms200::DecodeReading(mv->values[i], mv->units);
  }
  return line;
}

Result<sensors::LaserLine> Lms200Driver::NextLine(milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  const double per_try_s = model_.interlaced_sweeps() / 75.0 + kLineMargin_s +
                           WireTime(std::size_t(model_.telegram_bytes()), port_->baud());
  const milliseconds per_try(int(1000.0 * per_try_s));
  Error last{Error::Code::kTimeout, "nothing received"};
  bool reconnected = false;
  for (int attempt = 0; Remaining(deadline).count() > 0; ++attempt) {
    // Ctrl-C: no retry, no reconnect; the caller unwinds and the destructor quiets the device.
    if (StopRequested()) return tl::make_unexpected(StopError("LMS200 on " + config_.device));
    if (attempt > 0) ++stats_.retries;
    Result<Telegram> reply;
    double stamp_s = 0.0;
    if (config_.continuous) {
      reply = WaitFor(lms200::kRequestValues | lms200::kReplyBit, false,
                      Clock::now() + std::min(Remaining(deadline), per_try));
    } else {
      stamp_s = clock_();
      port_->DiscardInput();
      reader_.Clear();
      Result<void> sent = port_->Write(lms200::Encode(lms200::SingleScanRequest()));
      reply = sent ? WaitFor(lms200::kRequestValues | lms200::kReplyBit, true,
                             Clock::now() + std::min(Remaining(deadline), per_try))
                   : Result<Telegram>(tl::make_unexpected(sent.error()));
    }
    if (!reply) {
      last = reply.error();
      if (last.code != Error::Code::kDevice) continue;
      // The port hung up (unplugged): reopen and re-initialise once per line.
      if (reconnected) break;
      reconnected = true;
      if (Result<void> back = Reconnect(); !back) {
        return Fail(Error::Code::kDevice,
                    "LMS200 on " + config_.device + ": " + back.error().message);
      }
      continue;
    }
    if (config_.continuous) {
      // The line started a mirror turn plus its transfer before it arrived.
      stamp_s = clock_() - model_.interlaced_sweeps() / 75.0 -
                WireTime(lms200::Encode(*reply).size(), port_->baud());
    }
    Result<sensors::LaserLine> line = ToLine(*reply, stamp_s);
    if (line) return line;
    ++stats_.rejected_lines;
    last = line.error();
  }
  return Fail(last.code, "LMS200 on " + config_.device + ": no valid line within " +
                             std::to_string(timeout.count()) + " ms (last: " + last.message + ")");
}

}  // namespace pitchlab::hw
