#include "real_wrong_priors.hpp"

#include <cmath>
#include <utility>

#include "pitchlab/mapping/registration.hpp"

namespace pitchlab::benchmarks {
namespace {

// "The same pose": the reference is good to 0.5-1 deg (SOURCES.md).
constexpr double kSame_deg = 1.0, kSame_m = 0.05;

struct Offset {
  double along_m, turn_deg;
};

bool Same(const mapping::PoseError& e) {
  return e.rotation_deg <= kSame_deg && e.translation_m <= kSame_m;
}

// One registration and how its result compares with the reference and with ours.
nlohmann::json Case(const mapping::PointCloud& target, const mapping::PointCloud& source,
                    const mapping::RegistrationPrior& prior, const Eigen::Isometry3d& reference,
                    const Eigen::Isometry3d& ours, const mapping::RegistrationConfig& config) {
  const Result<mapping::RegistrationResult> r = mapping::Register(target, source, prior, config);
  if (!r) return {{"error", r.error().message}};
  const mapping::PoseError to_ref = mapping::ComparePoses(r->T_target_source, reference);
  const mapping::PoseError to_ours = mapping::ComparePoses(r->T_target_source, ours);
  return {{"success", r->success},
          {"outcome", mapping::ToString(r->outcome)},
          {"reason", r->reason},
          {"vs_reference",
           {{"rotation_deg", to_ref.rotation_deg}, {"translation_m", to_ref.translation_m}}},
          {"vs_ours",
           {{"rotation_deg", to_ours.rotation_deg}, {"translation_m", to_ours.translation_m}}},
          {"off_reference", r->success && !Same(to_ref)},
          {"off_ours", r->success && !Same(to_ours)}};
}

}  // namespace

nlohmann::json CheckWrongPriors(const WrongPriorPair& pair,
                                const mapping::RegistrationConfig& config) {
  const Offset offsets[] = {{1, 0},  {2, 0},  {3, 0},   {-1, 0}, {-2, 0},
                            {-3, 0}, {0, 10}, {0, -20}, {0, 30}, {2, 20}};
  nlohmann::json cases = nlohmann::json::array();
  int runs = 0, off_reference = 0, off_ours = 0;
  auto count = [&](nlohmann::json c) {
    if (!c.contains("error")) {
      ++runs;
      off_reference += c["off_reference"].get<bool>();
      off_ours += c["off_ours"].get<bool>();
    }
    cases.push_back(std::move(c));
  };
  for (const Offset& o : offsets) {
    for (const bool bounded : {true, false}) {
      mapping::RegistrationPrior prior;
      prior.source_sensor = pair.source_sensor;
      prior.target_sensor = pair.target_sensor;
      prior.odometry = pair.ours * mapping::PoseFromXyzRpyDeg(o.along_m, 0, 0, 0, 0, o.turn_deg);
      if (bounded) {  // half the offset: the truth lies outside the stated bound
        prior.odometry_uncertainty =
            mapping::GuessUncertainty{0.5 * std::abs(o.along_m), 0.5 * std::abs(o.turn_deg)};
      }
      nlohmann::json c = Case(*pair.target, *pair.source, prior, pair.reference, pair.ours, config);
      c["prior"] = {{"along_m", o.along_m}, {"turn_deg", o.turn_deg}, {"bounded", bounded}};
      count(std::move(c));
    }
  }
  // The wrong way round: the source as the target and the target as the source, with the pair's
  // own pose as the prior (its inverse would be right); held to the swapped pair's poses, ours and
  // the reference inverted.
  mapping::RegistrationPrior swapped;
  swapped.source_sensor = pair.target_sensor;
  swapped.target_sensor = pair.source_sensor;
  swapped.odometry = pair.ours;
  nlohmann::json c = Case(*pair.source, *pair.target, swapped, pair.reference.inverse(),
                          pair.ours.inverse(), config);
  c["prior"] = "the pair the wrong way round, our pose as the prior";
  count(std::move(c));
  return {{"runs", runs},
          {"successes_off_the_reference", off_reference},
          {"successes_off_ours", off_ours},
          {"cases", cases}};
}

}  // namespace pitchlab::benchmarks
