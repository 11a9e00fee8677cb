#pragma once

#include <mujoco/mujoco.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>

#include "scoped_temp_dir.hpp"

namespace pitchlab::worlds::test {

/// Owning handles for MuJoCo's C objects.
struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

/// Loads an MJCF file; fails the test with MuJoCo's message if it does not compile.
inline ModelPtr LoadModel(const std::filesystem::path& path) {
  char error[1000] = "";
  ModelPtr model(mj_loadXML(path.string().c_str(), nullptr, error, sizeof(error)));
  EXPECT_TRUE(model) << path << ": " << error;
  return model;
}

/// Height of the first surface straight below (x, y), cast from `from_z_m`; NaN when nothing is
/// hit.
inline double SurfaceHeight(const mjModel* m, mjData* d, double x, double y,
                            double from_z_m = 200.0) {
  const mjtNum origin[3] = {x, y, from_z_m};
  const mjtNum down[3] = {0.0, 0.0, -1.0};
  int geom = -1;
  const mjtNum distance = mj_ray(m, d, origin, down, nullptr, 1, -1, &geom);
  return distance < 0 ? std::nan("") : from_z_m - distance;
}

/// A fresh, empty folder under the system temp dir, removed with the object.
using test_support::ScopedTempDir;

/// The whole file as bytes.
inline std::string ReadBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// Writes `text` to `path`.
inline void WriteText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

}  // namespace pitchlab::worlds::test
