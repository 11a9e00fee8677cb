#pragma once
// How much memory this machine has: sizes read from files and options are checked against it
// before they are allocated (a std::bad_alloc names nothing a user can act on).

#include <unistd.h>

#include <limits>

namespace pitchlab::mapping {

/// Physical memory [bytes]; +inf when the system does not say, so that nothing is refused for it.
inline double PhysicalMemoryBytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page_bytes = ::sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page_bytes <= 0) return std::numeric_limits<double>::infinity();
  return static_cast<double>(pages) * static_cast<double>(page_bytes);
}

}  // namespace pitchlab::mapping
