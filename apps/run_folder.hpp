#pragma once
// A run's output folder, written atomically: everything goes into a hidden sibling first, and the
// folder appears under its name only when Commit() renames it, so a failed or interrupted run
// never leaves a half-written folder behind.

#include <filesystem>
#include <string>

namespace pitchlab::apps {

class RunFolder {
 public:
  /// Prepares `<parent>/.<name>.partial-<pid>`. Throws std::runtime_error when `final_path`
  /// already exists (runs are never overwritten) or the staging folder cannot be made.
  explicit RunFolder(std::filesystem::path final_path);
  ~RunFolder();  ///< removes the staging folder unless committed
  RunFolder(const RunFolder&) = delete;
  RunFolder& operator=(const RunFolder&) = delete;

  /// Where to write `relative` inside the staging folder (parent folders are created).
  std::filesystem::path File(const std::string& relative) const;
  /// Renames the staging folder to the final path. Throws std::runtime_error on failure.
  void Commit();
  const std::filesystem::path& final_path() const { return final_; }

 private:
  std::filesystem::path final_, staging_;
  bool committed_ = false;
};

/// The output folder of a tool that may write into an existing folder (map, plan): files are
/// written into a hidden sibling (".NAME.partial") and moved in only when all are written, so a
/// failure part way leaves neither a half-written folder nor half of a file set.
class StagedFolder {
 public:
  explicit StagedFolder(const std::filesystem::path& out);  ///< throws std::filesystem_error
  ~StagedFolder();  ///< removes the staging folder
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  /// Where to write the file `name` now.
  std::filesystem::path operator/(const std::string& name) const { return stage_ / name; }
  /// Moves every file into the output folder (created; files of the same name replaced).
  void Commit() const;

 private:
  std::filesystem::path out_, stage_;
};

/// Writes `text` to `path` (the folder exists); throws std::runtime_error naming the path.
void WriteTextFile(const std::filesystem::path& path, const std::string& text);
/// Reads a whole file; throws std::runtime_error naming the path.
std::string ReadBinaryFile(const std::filesystem::path& path);

}  // namespace pitchlab::apps
