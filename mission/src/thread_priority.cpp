#include "thread_priority.hpp"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>

namespace pitchlab::mission {

void LowerThisThreadsPriority(int by) {
  constexpr int kNicest = 19;  // Linux nice values: -20 (first) .. 19 (last)
  const auto tid = static_cast<id_t>(syscall(SYS_gettid));
  errno = 0;
  const int nice = getpriority(PRIO_PROCESS, tid);
  if (errno == 0) setpriority(PRIO_PROCESS, tid, std::min(kNicest, nice + by));
}

}  // namespace pitchlab::mission
