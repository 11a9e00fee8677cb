#pragma once
// Result type for expected run-time outcomes (timeouts, device faults, no return): STYLE.md "Errors" 3.

#include <string>
#include <utility>

#include <tl/expected.hpp>

namespace pitchlab {

/// What went wrong, in words a user can act on; `code` lets callers branch without parsing text.
struct Error {
  enum class Code { kInvalidArgument, kTimeout, kDevice, kProtocol, kNotFound, kFailed };
  Code code = Code::kFailed;
  std::string message;
};

template <typename T>
using Result = tl::expected<T, Error>;

/// Shorthand for returning an error: `return Fail(Error::Code::kTimeout, "no line within 2 s");`.
inline tl::unexpected<Error> Fail(Error::Code code, std::string message) {
  return tl::make_unexpected(Error{code, std::move(message)});
}

}  // namespace pitchlab
