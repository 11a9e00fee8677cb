#pragma once
// Checks of a command's output path, made before any work: a mistake in --out shows at once,
// not after a 50-second run or a simulated scan (issue 18).

#include <filesystem>
#include <string>

namespace pitchlab::apps {

/// `path`, the value of `--<option>`, can become a new folder: not empty (CliError), not there
/// yet, and its nearest existing ancestor a folder this process may write in (missing parents are
/// created with it); else std::runtime_error naming the option and the path. run, map and plan all refuse an existing folder: outputs are never
/// overwritten or mixed with an earlier run's.
void CheckNewFolder(const std::string& option, const std::filesystem::path& path);

/// `path`, the value of `--<option>`, can be written as a file: not empty (CliError), not a
/// folder, its parent an existing folder this process may write in (std::runtime_error). An
/// existing file is replaced (atomically, by the writers).
void CheckOutputFile(const std::string& option, const std::filesystem::path& path);

}  // namespace pitchlab::apps
