#include "pitchlab/hw/emulated_device.hpp"

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "baud_code.hpp"

namespace pitchlab::hw {
namespace {

constexpr int kIdlePeriodMs = 5;

}  // namespace

EmulatedDevice::EmulatedDevice(std::string name, int baud, std::string link_path)
    : name_(std::move(name)), baud_(baud), link_path_(std::move(link_path)) {
  std::string made_dir;  // the folder made here, if any
  if (link_path_.empty()) {
    std::error_code no_tmp;
    const std::filesystem::path tmp = std::filesystem::temp_directory_path(no_tmp);  // TMPDIR
    std::string dir = (no_tmp ? std::filesystem::path("/tmp") : tmp) / "pitchlab-hw-XXXXXX";
    if (::mkdtemp(dir.data()) == nullptr) {
      throw std::runtime_error("emulator " + name_ + ": cannot create the folder " + dir + ": " +
                               std::strerror(errno));
    }
    made_dir = dir;
    link_path_ = dir + "/" + name_;
    own_link_dir_ = true;
  }
  try {
    OpenPty();
  } catch (...) {  // no destructor runs: the folder made above goes here
    if (!made_dir.empty()) ::rmdir(made_dir.c_str());
    throw;
  }
}

EmulatedDevice::~EmulatedDevice() {
  Stop();
  ClosePty();
  std::error_code ignored;
  std::filesystem::remove(link_path_, ignored);
  if (own_link_dir_)
    std::filesystem::remove(std::filesystem::path(link_path_).parent_path(), ignored);
}

void EmulatedDevice::OpenPty() {
  int master = -1, slave = -1;
  char slave_name[256] = {};
  if (::openpty(&master, &slave, slave_name, nullptr, nullptr) != 0) {
    throw std::runtime_error("emulator " + name_ + ": openpty failed: " + std::strerror(errno));
  }
  termios tio{};
  ::tcgetattr(slave, &tio);
  ::cfmakeraw(&tio);
  ::cfsetispeed(&tio, SpeedCode(baud_));
  ::cfsetospeed(&tio, SpeedCode(baud_));
  ::tcsetattr(slave, TCSANOW, &tio);
  ::fcntl(master, F_SETFL, ::fcntl(master, F_GETFL) | O_NONBLOCK);
  ::fcntl(master, F_SETFD, FD_CLOEXEC);
  ::fcntl(slave, F_SETFD, FD_CLOEXEC);
  std::error_code ignored;
  std::filesystem::remove(link_path_, ignored);
  if (::symlink(slave_name, link_path_.c_str()) != 0) {
    const std::string message = "emulator " + name_ + ": cannot link " + link_path_ + " -> " +
                                slave_name + ": " + std::strerror(errno);
    ::close(master);
    ::close(slave);
    throw std::runtime_error(message);
  }
  held_slave_ = slave;
  master_ = master;
  plugged_ = true;
}

void EmulatedDevice::ClosePty() {
  std::lock_guard<std::mutex> lock(mutex_);
  plugged_ = false;
  const int master = master_.exchange(-1);
  if (master >= 0) ::close(master);
  if (held_slave_ >= 0) ::close(held_slave_);
  held_slave_ = -1;
}

void EmulatedDevice::Unplug() {
  ClosePty();
  std::error_code ignored;
  std::filesystem::remove(link_path_, ignored);
}

void EmulatedDevice::Replug() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (plugged_) return;
  }
  OpenPty();
  replugged_ = true;
}

void EmulatedDevice::SetPowered(bool on) {
  const bool was = powered_.exchange(on);
  if (on && !was) replugged_ = true;  // the I/O thread runs OnPowerOn
}

std::size_t EmulatedDevice::unread_bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  int queued = 0;
  if (held_slave_ < 0 || ::ioctl(held_slave_, FIONREAD, &queued) != 0) return 0;
  return std::size_t(queued);
}

void EmulatedDevice::SetFaults(const FaultPlan& plan) {
  std::lock_guard<std::mutex> lock(mutex_);
  plan_ = plan;
  rng_.seed(plan.seed);
}

DeviceStats EmulatedDevice::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

void EmulatedDevice::CountRequest(bool well_formed) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++(well_formed ? stats_.requests : stats_.bad_requests);
}

void EmulatedDevice::Start() {
  running_ = true;
  thread_ = std::thread([this] { Loop(); });
}

void EmulatedDevice::Stop() {
  running_ = false;
  if (thread_.joinable()) thread_.join();
}

bool EmulatedDevice::DriverBaudMatches() const {
  std::lock_guard<std::mutex> lock(mutex_);
  termios tio{};
  if (held_slave_ < 0 || ::tcgetattr(held_slave_, &tio) != 0) return false;
  return ::cfgetispeed(&tio) == SpeedCode(baud_);
}

void EmulatedDevice::Loop() {
  std::uint8_t buffer[512];
  while (running_) {
    if (replugged_.exchange(false)) OnPowerOn();
    const int fd = master_;
    if (fd < 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(kIdlePeriodMs));
      continue;
    }
    pollfd p{fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, kIdlePeriodMs);
    if (ready > 0 && (p.revents & POLLIN)) {
      const ssize_t n = ::read(fd, buffer, sizeof(buffer));
      if (n > 0 && powered_) OnBytes(buffer, std::size_t(n));  // unpowered: bytes are lost
    } else if (ready > 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(kIdlePeriodMs));
    }
    if (powered_) OnIdle();
  }
}

void EmulatedDevice::Send(const std::vector<std::uint8_t>& message,
                          std::optional<std::chrono::steady_clock::time_point> not_before) {
  if (!powered_) return;
  std::vector<std::uint8_t> bytes = message;
  FaultPlan::Kind fault = FaultPlan::Kind::kNone;
  int delay_ms = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.messages_sent;
    std::uniform_real_distribution<double> chance(0.0, 1.0);
    if (plan_.kind != FaultPlan::Kind::kNone && plan_.messages != 0 && !bytes.empty() &&
        chance(rng_) < plan_.probability) {
      fault = plan_.kind;
      delay_ms = plan_.delay_ms;
      if (plan_.messages > 0) --plan_.messages;
      ++stats_.faults;
      std::uniform_int_distribution<std::size_t> pick(0, bytes.size() - 1);
      const std::size_t at = pick(rng_);
      switch (fault) {
        case FaultPlan::Kind::kDrop:
          bytes.erase(bytes.begin() + long(at));
          break;
        case FaultPlan::Kind::kFlip:
          bytes[at] ^= std::uint8_t(1u << (rng_() % 8));
          break;
        case FaultPlan::Kind::kDuplicate:
          bytes.insert(bytes.begin() + long(at), bytes[at]);
          break;
        case FaultPlan::Kind::kSilent:
          bytes.clear();
          break;
        case FaultPlan::Kind::kDelay:
        case FaultPlan::Kind::kNone:
          break;
      }
    }
  }
  const auto start = not_before.value_or(std::chrono::steady_clock::now());
  if (fault == FaultPlan::Kind::kDelay) {
    const std::size_t half = bytes.size() / 2;
    WriteAtLineRate(bytes.data(), half, start);
    line_free_at_ += std::chrono::milliseconds(delay_ms);
    WriteAtLineRate(bytes.data() + half, bytes.size() - half, line_free_at_);
    return;
  }
  WriteAtLineRate(bytes.data(), bytes.size(), start);
}

void EmulatedDevice::WriteAtLineRate(const std::uint8_t* bytes, std::size_t size,
                                     std::chrono::steady_clock::time_point not_before) {
  // A UART puts 10 bits a byte (8N1) on the line, one message after the other. Writing the
  // message whole when its last byte would have arrived keeps every client's inter-byte timeout
  // (sicktoolbox: 35 ms) out of reach of the scheduler: a write in small paced chunks stalled
  // 52 ms between chunks on a loaded machine. Sleeping to an absolute time keeps a late wake-up
  // from adding up over a stream.
  using Clock = std::chrono::steady_clock;
  const auto wire = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(double(size) * 10.0 / double(baud_)));
  // The first byte leaves when the line is free (the previous message handed over) and not
  // before `not_before`.
  line_free_at_ = std::max({line_free_at_, last_write_, not_before}) + wire;
  std::this_thread::sleep_until(line_free_at_);
  last_write_ = Clock::now();
  std::size_t sent = 0;
  while (sent < size && running_) {
    const int fd = master_;
    if (fd < 0) return;  // unplugged mid-message
    const ssize_t n = ::write(fd, bytes + sent, size - sent);
    if (n < 0 && errno == EINTR) continue;
    // Nobody reads and the pty's buffer is full (an overrun): the rest of the message is lost.
    if (n < 0) return;
    sent += std::size_t(n);
  }
}

}  // namespace pitchlab::hw
