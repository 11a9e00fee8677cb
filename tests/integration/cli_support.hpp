#pragma once
// What the CLI integration tests share: running the pitchlab binary and reading files back.

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace pitchlab::cli_test {

/// How one `pitchlab` invocation ended and what it printed.
struct CliResult {
  int exit_code = -1;  ///< -1 when it did not exit normally
  std::string out, err;
};

/// A whole file as bytes (empty when it cannot be read).
inline std::string Slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

/// Runs `pitchlab <args>`; stdout and stderr go through files in `scratch_dir`.
inline CliResult RunPitchlab(const std::string& args, const std::filesystem::path& scratch_dir) {
  const std::filesystem::path out = scratch_dir / "stdout.txt", err = scratch_dir / "stderr.txt";
  const std::string command =
      std::string(PITCHLAB_CLI) + " " + args + " >" + out.string() + " 2>" + err.string();
  const int status = std::system(command.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, Slurp(out), Slurp(err)};
}

}  // namespace pitchlab::cli_test
