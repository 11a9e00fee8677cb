#pragma once
// Progress lines for long steps of a command (issue 18: ~10 s silent looks hung).

#include <functional>
#include <string>

namespace pitchlab::apps {

/// A progress callback (done, total) that prints "<prefix>: 25 % (n of total <unit>)" to stderr at
/// each quarter, or nothing when `quiet`. Four lines: enough to see it move, few enough for a log.
std::function<void(int done, int total)> QuarterProgress(std::string prefix, std::string unit,
                                                         bool quiet);

}  // namespace pitchlab::apps
