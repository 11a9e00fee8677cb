#include "pitchlab/hw/pioneer_params.hpp"

#include <algorithm>
#include <cctype>

namespace pitchlab::hw {
namespace {

// ARIA params/*.p, "Conversion factors" section (AngleConvFactor is printed there rounded to
// 0.00153; ArRobotTypes and p2os's robot_params carry 0.001534 = 2 pi / 4096). The "-sh" models
// run ARCOS, which reports mm and mm/s (factor 1); the older uARCS / P2OS models report wheel
// encoder units scaled by DistConvFactor (p3at.p: 0.465 "multiplier to mm from robot units").
// Vel2Divisor is 20 in every P3 file (ArRobotParams' default; p3at.p states it).
const PioneerParams kModels[] = {
    {"p3at", 0.001534, 0.465, 1.0, 20.0},    {"p3at-sh", 0.001534, 1.0, 1.0, 20.0},
    {"p3atiw", 0.001534, 0.3768, 1.0, 20.0}, {"p3atiw-sh", 0.001534, 1.0, 1.0, 20.0},
    {"p3dx", 0.001534, 0.485, 1.0, 20.0},    {"p3dx-sh", 0.001534, 1.0, 1.0, 20.0},
};

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

}  // namespace

Result<PioneerParams> FindPioneerParams(const std::string& subclass) {
  const std::string wanted = Lower(subclass);
  std::string known;
  for (const PioneerParams& p : kModels) {
    if (p.subclass == wanted) return p;
    known += (known.empty() ? "" : ", ") + p.subclass;
  }
  return Fail(Error::Code::kInvalidArgument,
              "robot subclass '" + subclass +
                  "' is not a Pioneer P3 model with known conversion factors (" + known + ")");
}

}  // namespace pitchlab::hw
