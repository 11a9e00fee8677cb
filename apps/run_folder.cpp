#include "run_folder.hpp"

#include <unistd.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace pitchlab::apps {

namespace fs = std::filesystem;

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
}

RunFolder::~RunFolder() {
  if (committed_) return;
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
}

fs::path RunFolder::File(const std::string& relative) const {
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
}

StagedFolder::StagedFolder(const fs::path& out) : out_(out.lexically_normal()) {
  if (!out_.has_filename()) out_ = out_.parent_path();
  stage_ = out_.parent_path() / ("." + out_.filename().string() + ".partial");
  fs::remove_all(stage_);
  fs::create_directories(stage_);
}

StagedFolder::~StagedFolder() {
  std::error_code ignored;
  fs::remove_all(stage_, ignored);
}

void StagedFolder::Commit() const {
  fs::create_directories(out_);
  for (const auto& e : fs::directory_iterator(stage_)) fs::rename(e.path(), out_ / e.path().filename());
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

}  // namespace pitchlab::apps
