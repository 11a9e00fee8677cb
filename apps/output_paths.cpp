#include "output_paths.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "cli_args.hpp"

namespace pitchlab::apps {
namespace {

namespace fs = std::filesystem;

// The folder the output will be created in must take new entries. A new folder's missing parents
// are created with it (`runs/` on a first run), so its nearest existing ancestor is checked; a
// file's parent must exist (the writers create no folders).
void CheckParent(const std::string& option, const fs::path& path, bool create_parents) {
  auto up = [](const fs::path& p) { return p.has_parent_path() ? p.parent_path() : fs::path("."); };
  fs::path parent = up(path);
  std::error_code ec;
  // "runs" (a relative path of one name) has no parent_path: its parent is the working folder.
  while (create_parents && !fs::exists(parent, ec) && up(parent) != parent) parent = up(parent);
  if (!fs::is_directory(parent, ec)) {
    throw std::runtime_error("--" + option + " '" + path.string() + "': '" + parent.string() +
                             (fs::exists(parent, ec) ? "' is not a folder" : "' does not exist"));
  }
  if (::access(parent.c_str(), W_OK | X_OK) != 0) {
    const int error = errno;  // read at once: later calls may overwrite it
    throw std::runtime_error("--" + option + " '" + path.string() + "': cannot write in '" +
                             parent.string() + "': " + std::strerror(error));
  }
}

fs::path WithoutTrailingSlash(const fs::path& path) {
  return path.has_filename() ? path : path.parent_path();
}

}  // namespace

void CheckNewFolder(const std::string& option, const fs::path& given) {
  if (given.empty()) throw CliError("--" + option + " is empty: give a folder to create");
  const fs::path path = WithoutTrailingSlash(given);
  std::error_code ec;
  if (fs::exists(fs::symlink_status(path, ec))) {
    throw std::runtime_error("output folder '" + path.string() +
                             "' already exists; give a new --" + option);
  }
  CheckParent(option, path, /*create_parents=*/true);
}

void CheckOutputFile(const std::string& option, const fs::path& path) {
  if (path.empty()) throw CliError("--" + option + " is empty: give a file to write");
  std::error_code ec;
  if (!path.has_filename() || fs::is_directory(path, ec)) {
    throw std::runtime_error("--" + option + " '" + path.string() +
                             "' is a folder; give a file name");
  }
  CheckParent(option, path, /*create_parents=*/false);
}

}  // namespace pitchlab::apps
