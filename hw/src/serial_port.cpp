#include "pitchlab/hw/serial_port.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "baud_code.hpp"

namespace pitchlab::hw {
namespace {

std::string SystemError(const std::string& what, const std::string& device) {
  return what + " " + device + ": " + std::strerror(errno);
}

}  // namespace

bool IsSupportedBaud(int baud) { return SpeedCode(baud) != B0; }

double WireTime(std::size_t bytes, int baud) { return double(bytes) * 10.0 / double(baud); }

SerialPort::SerialPort(std::string device, int baud) : device_(std::move(device)), baud_(baud) {
  if (!IsSupportedBaud(baud)) {
    throw std::invalid_argument("serial port " + device_ + ": baud " + std::to_string(baud) +
                                " is not supported (9600, 19200, 38400, 115200, 500000)");
  }
  if (Result<void> opened = OpenAndConfigure(); !opened) {
    throw std::runtime_error(opened.error().message);
  }
}

SerialPort::~SerialPort() { Close(); }

void SerialPort::Close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

Result<void> SerialPort::OpenAndConfigure() {
  Close();
  const int fd = ::open(device_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return Fail(Error::Code::kDevice, SystemError("cannot open serial port", device_));
  termios tio{};
  if (::tcgetattr(fd, &tio) != 0) {
    const std::string message = SystemError("not a serial port (tcgetattr)", device_);
    ::close(fd);
    return Fail(Error::Code::kDevice, message);
  }
  // Raw 8N1: no echo, no line editing, no translation, no flow control.
  ::cfmakeraw(&tio);
  tio.c_cflag |= CLOCAL | CREAD;
  tio.c_cflag &= ~(CSTOPB | PARENB | CRTSCTS);
  tio.c_iflag &= ~(IXON | IXOFF | IXANY);
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  ::cfsetispeed(&tio, SpeedCode(baud_));
  ::cfsetospeed(&tio, SpeedCode(baud_));
  if (::tcsetattr(fd, TCSANOW, &tio) != 0) {
    const std::string message = SystemError("cannot configure serial port", device_);
    ::close(fd);
    return Fail(Error::Code::kDevice, message);
  }
  ::tcflush(fd, TCIOFLUSH);
  fd_ = fd;
  return {};
}

Result<void> SerialPort::SetBaud(int baud) {
  if (!IsSupportedBaud(baud)) {
    return Fail(Error::Code::kInvalidArgument,
                device_ + ": baud " + std::to_string(baud) + " is not supported");
  }
  if (fd_ < 0) return Fail(Error::Code::kDevice, device_ + " is not open");
  termios tio{};
  if (::tcgetattr(fd_, &tio) != 0 || ::cfsetispeed(&tio, SpeedCode(baud)) != 0 ||
      ::cfsetospeed(&tio, SpeedCode(baud)) != 0 || ::tcsetattr(fd_, TCSADRAIN, &tio) != 0) {
    return Fail(Error::Code::kDevice, SystemError("cannot set baud on", device_));
  }
  baud_ = baud;
  return {};
}

Result<void> SerialPort::Write(const std::vector<std::uint8_t>& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    if (fd_ < 0) return Fail(Error::Code::kDevice, device_ + " is not open");
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += std::size_t(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno == EAGAIN) {
      pollfd p{fd_, POLLOUT, 0};
      if (::poll(&p, 1, 1000) <= 0 || (p.revents & (POLLHUP | POLLERR))) {
        return Fail(Error::Code::kDevice, device_ + ": cannot write (device gone or stuck)");
      }
      continue;
    }
    return Fail(Error::Code::kDevice, SystemError("write failed on", device_));
  }
  return {};
}

Result<std::size_t> SerialPort::Read(std::uint8_t* buffer, std::size_t max,
                                     std::chrono::milliseconds timeout) {
  if (fd_ < 0) return Fail(Error::Code::kDevice, device_ + " is not open");
  pollfd p{fd_, POLLIN, 0};
  int ready = 0;
  do {
    ready = ::poll(&p, 1, int(timeout.count()));
  } while (ready < 0 && errno == EINTR);
  if (ready < 0) return Fail(Error::Code::kDevice, SystemError("poll failed on", device_));
  if (ready == 0) return Fail(Error::Code::kTimeout, device_ + ": no data");
  const ssize_t n = ::read(fd_, buffer, max);
  if (n > 0) return std::size_t(n);
  if (n < 0 && (errno == EAGAIN || errno == EINTR)) return std::size_t{0};
  // A hang-up (EIO on a pty whose master closed, 0 bytes on a vanished USB adapter): unplugged.
  return Fail(Error::Code::kDevice, device_ + ": device hung up (unplugged?)");
}

void SerialPort::DiscardInput() {
  if (fd_ >= 0) ::tcflush(fd_, TCIFLUSH);
}

Result<void> SerialPort::Reopen() { return OpenAndConfigure(); }

}  // namespace pitchlab::hw
