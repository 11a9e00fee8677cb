#pragma once
// The report's 3D view: three.js (Debian's libjs-three, read when the report is written and
// inlined, so the page works offline) drawing a Scene3D with mouse orbit, zoom and pan.

#include <filesystem>
#include <string>

#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mission {

/// three.js and its OrbitControls, the browser (UMD) builds.
struct ThreeJs {
  std::string three, orbit_controls;
};

/// Where CMake found libjs-three when the project was configured; empty when it was not found.
std::filesystem::path DefaultThreeJsDir();

/// Reads three.min.js and examples/js/controls/OrbitControls.js under `dir`. Fails (kNotFound)
/// naming the missing file and the Debian package that provides it.
[[nodiscard]] Result<ThreeJs> LoadThreeJs(const std::filesystem::path& dir);

/// The view: a canvas holder (#view3d), layer toggles, the scene JSON (SceneJson) and the scripts.
/// When it has drawn, #view3d carries data-status="ok" and data-drawn-pixels (pixels that differ
/// from the background); on failure data-status="error" and the reason in the page.
std::string ViewerHtml(const std::string& scene_json, const ThreeJs& three);

/// What the page shows in the view's place when three.js is missing: the reason and the fix.
std::string ViewerUnavailableHtml(const std::string& why);

}  // namespace pitchlab::mission
