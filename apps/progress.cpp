#include "progress.hpp"

#include <cstdio>
#include <memory>

namespace pitchlab::apps {

std::function<void(int done, int total)> QuarterProgress(std::string prefix, std::string unit,
                                                         bool quiet) {
  if (quiet) return [](int, int) {};
  auto last_quarter = std::make_shared<int>(0);
  return [prefix = std::move(prefix), unit = std::move(unit), last_quarter](int done, int total) {
    if (total <= 0) return;
    const int quarter = 4 * done / total;
    if (quarter <= *last_quarter) return;
    *last_quarter = quarter;
    std::fprintf(stderr, "%s: %d %% (%d of %d %s)\n", prefix.c_str(), 25 * quarter, done, total,
                 unit.c_str());
  };
}

}  // namespace pitchlab::apps
