#include "mujoco_handlers.hpp"

#include <mutex>
#include <stdexcept>

#include <mujoco/mujoco.h>

namespace pitchlab::sim {
namespace {

std::mutex warnings_mutex;
std::vector<std::string> warnings;

void ThrowOnError(const char* message) {
  throw std::runtime_error(std::string("MuJoCo error: ") + message);
}

void CollectWarning(const char* message) {
  std::lock_guard<std::mutex> lock(warnings_mutex);
  warnings.emplace_back(message);
}

}  // namespace

void InstallMujocoHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_error = ThrowOnError;
    mju_user_warning = CollectWarning;
  });
}

std::vector<std::string> TakeMujocoWarnings() {
  std::lock_guard<std::mutex> lock(warnings_mutex);
  std::vector<std::string> out;
  out.swap(warnings);
  return out;
}

}  // namespace pitchlab::sim
