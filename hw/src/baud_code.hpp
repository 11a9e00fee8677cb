#pragma once
// termios speed code of a baud rate, shared by the serial port and the pty emulators.

#include <termios.h>

namespace pitchlab::hw {

/// B9600 ... B500000 for the rates the drivers use; B0 for any other.
inline speed_t SpeedCode(int baud) {
  switch (baud) {
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 115200:
      return B115200;
    case 500000:
      return B500000;
    default:
      return B0;
  }
}

}  // namespace pitchlab::hw
