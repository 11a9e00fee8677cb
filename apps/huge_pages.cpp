#include "huge_pages.hpp"

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <iterator>

namespace pitchlab::apps {

namespace {

constexpr const char* kTunable = "glibc.malloc.hugetlb";

bool ThpOnRequestOnly() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return text.find("[madvise]") != std::string::npos;
}

}  // namespace

std::string WithHugePageMalloc(const std::string& current) {
  if (current.find(kTunable) != std::string::npos) return "";
  const std::string mine = std::string(kTunable) + "=1";
  return current.empty() ? mine : current + ":" + mine;
}

void UseHugePagesForLargeAllocations(char** argv) {
#if defined(__SANITIZE_ADDRESS__)
  (void)argv;
#else
  const char* current = std::getenv("GLIBC_TUNABLES");
  const std::string tunables = WithHugePageMalloc(current ? current : "");
  if (tunables.empty() || !ThpOnRequestOnly()) return;
  if (setenv("GLIBC_TUNABLES", tunables.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  // Still here: the exec failed. Run on without; the variable stays set for child processes,
  // which then need no exec of their own.
#endif
}

}  // namespace pitchlab::apps
