#pragma once
// Private: process-wide MuJoCo error/warning handlers (STYLE.md "Errors").

#include <string>
#include <vector>

namespace pitchlab::sim {

/// Installs (once) an mju_user_error handler that throws std::runtime_error and an
/// mju_user_warning handler that collects the text for TakeMujocoWarnings.
void InstallMujocoHandlers();

/// Warnings collected since the last call (all simulations of the process).
std::vector<std::string> TakeMujocoWarnings();

}  // namespace pitchlab::sim
