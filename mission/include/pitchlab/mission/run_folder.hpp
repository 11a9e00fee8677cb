#pragma once
// A run's output folder, written atomically: everything goes into a hidden sibling first, and the
// folder appears under its name only when Commit() renames it, so a failed or interrupted run
// never leaves a half-written folder behind.

#include <filesystem>
#include <string>

namespace pitchlab::mission {

class RunFolder {
 public:
  /// Prepares `<parent>/.<name>.partial-<pid>`. Throws std::runtime_error when `final_path`
  /// already exists (runs are never overwritten) or the staging folder cannot be made. The
  /// staging folder is registered with RegisterCleanup: SIGINT / SIGTERM remove it too.
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
  int cleanup_id_ = -1;  ///< RegisterCleanup's
};

/// `message` with every staging folder of this process's RunFolders replaced by the folder's final
/// name: an error from a writer names the hidden `.NAME.partial-PID/x` it was writing, which the
/// failed RunFolder has removed; the user knows NAME.
std::string WithFinalPaths(std::string message);

/// Writes `text` to `path` (the folder exists); throws std::runtime_error naming the path.
void WriteTextFile(const std::filesystem::path& path, const std::string& text);
/// Reads a whole file; throws std::runtime_error naming the path.
std::string ReadBinaryFile(const std::filesystem::path& path);

}  // namespace pitchlab::mission
