#include "pitchlab/mission/run_folder.hpp"

#include <unistd.h>

#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "pitchlab/mission/cleanup_registry.hpp"

namespace pitchlab::mission {

namespace fs = std::filesystem;

namespace {
std::mutex g_names_mutex;
std::map<std::string, std::string> g_final_names;  // staging folder -> final path, as given
}  // namespace

std::string WithFinalPaths(std::string message) {
  std::lock_guard<std::mutex> lock(g_names_mutex);
  for (const auto& [staging, final_name] : g_final_names) {
    for (std::size_t at = message.find(staging); at != std::string::npos;
         at = message.find(staging, at + final_name.size())) {
      message.replace(at, staging.size(), final_name);
    }
  }
  return message;
}

RunFolder::RunFolder(fs::path final_path) : final_(std::move(final_path)) {
  if (final_.filename().empty()) final_ = final_.parent_path();
  if (fs::exists(final_)) {
    throw std::runtime_error("output folder '" + final_.string() +
                             "' already exists; give a new --out");
  }
  const fs::path parent = final_.has_parent_path() ? final_.parent_path() : fs::path(".");
  staging_ = parent / ("." + final_.filename().string() + ".partial-" + std::to_string(::getpid()));
  std::error_code ec;
  fs::create_directories(staging_, ec);
  if (ec) {
    throw std::runtime_error("cannot create output folder under '" + parent.string() +
                             "': " + ec.message());
  }
  {
    std::lock_guard<std::mutex> lock(g_names_mutex);
    g_final_names[staging_.string()] = final_.string();
  }
  cleanup_id_ = RegisterCleanup(
      [staging = staging_](int) {
        std::error_code ignored;
        return fs::remove_all(staging, ignored) > 0;
      },
      "the unfinished output folder '" + final_.string() + "'");
}

RunFolder::~RunFolder() {
  UnregisterCleanup(cleanup_id_);
  if (committed_) return;
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
}

fs::path RunFolder::File(const std::string& relative) const {
  WaitIfInterrupted();  // the watcher is removing the folder: do not make it again
  const fs::path path = staging_ / relative;
  fs::create_directories(path.parent_path());
  return path;
}

void RunFolder::Commit() {
  std::error_code ec;
  fs::rename(staging_, final_, ec);
  if (ec) {
    throw std::runtime_error("cannot move the run to '" + final_.string() + "': " + ec.message());
  }
  committed_ = true;
  UnregisterCleanup(cleanup_id_);
}

void WriteTextFile(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw std::runtime_error("cannot write '" + path.string() + "'");
}

std::string ReadBinaryFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read '" + path.string() + "'");
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

}  // namespace pitchlab::mission
