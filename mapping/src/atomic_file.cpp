#include "pitchlab/mapping/atomic_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace pitchlab::mapping {

Result<void> WriteFileAtomically(const std::string& path, const std::string& bytes) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      return Fail(Error::Code::kInvalidArgument, path + ": cannot write: " + std::strerror(errno));
    }
    errno = 0;
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();  // closing writes what is buffered, and may be where a full disk shows
    if (out.fail()) {
      // What the system said (a full disk, a file size limit), when it said anything.
      const std::string why = errno != 0 ? std::strerror(errno) : "write failed";
      std::remove(tmp.c_str());  // a full disk leaves no partial file behind
      return Fail(Error::Code::kFailed, path + ": cannot write: " + why);
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    return Fail(Error::Code::kFailed, path + ": rename failed: " + ec.message());
  }
  return {};
}

}  // namespace pitchlab::mapping
