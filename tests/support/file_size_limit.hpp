#pragma once
// A full disk in a unit test, portably (no tmpfs to mount): a child process whose files may not
// grow past a limit, so that a write beyond it fails with EFBIG as one on a full disk fails with
// ENOSPC. The limit and the ignored SIGXFSZ stay in the child.

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <functional>

namespace pitchlab::test_support {

/// Runs `body` in a child whose files may not exceed `max_file_bytes`; returns the exit code
/// `body` returned, or -1 when the child could not be made or did not exit normally.
inline int InChildWithFileSizeLimit(rlim_t max_file_bytes, const std::function<int()>& body) {
  const pid_t pid = ::fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    std::signal(SIGXFSZ, SIG_IGN);  // the write then fails with EFBIG instead of killing the child
    const rlimit limit{max_file_bytes, max_file_bytes};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    ::_exit(body());
  }
  int status = 0;
  if (::waitpid(pid, &status, 0) != pid || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

}  // namespace pitchlab::test_support
