#pragma once
// `pitchlab bench --compare A B`: how sweep B differs from sweep A, world by world.

#include <string>

namespace pitchlab::apps {

/// Prints, for every world of either sweep, each metric's median in A and B, the change, its 95 %
/// bootstrap interval and a permutation test's p-value, and success counts with Fisher's exact
/// test (a table on stdout; with `as_json` the JSON on stdout and the table on stderr). `a` and
/// `b` are bench folders or runs.jsonl files. Returns the exit code (0).
int CompareSweeps(const std::string& a, const std::string& b, bool as_json);

}  // namespace pitchlab::apps
