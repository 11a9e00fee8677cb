#include "atomic_file.hpp"

#include <filesystem>
#include <fstream>

namespace pitchlab::planning {

Result<void> WriteFileAtomically(const std::string& file, const std::string& bytes) {
  const std::string tmp = file + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return Fail(Error::Code::kInvalidArgument, file + ": cannot write");
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out.flush()) {
      out.close();
      std::error_code ignored;
      std::filesystem::remove(tmp, ignored);  // a full disk leaves no partial file behind
      return Fail(Error::Code::kFailed, file + ": write failed");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) return Fail(Error::Code::kFailed, file + ": rename failed: " + ec.message());
  return {};
}

}  // namespace pitchlab::planning
