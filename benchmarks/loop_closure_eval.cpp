// loop_closure_eval: MapBuilder with and without loop closure (issue 20) on simulated sequences
// that return to their start, scored against the simulator's ground truth; prints JSON.
//
//   build/benchmarks/loop_closure_eval [--worlds office,urban] [--scale S] [--legacy-lms200]
//
// Each world has a route of stops that comes back to where it began. Scans are simulated with the
// default SimRig (one robot: one LMS200 seed and mount error for the whole route) unless
// --legacy-lms200 (the registration tests' constant-noise, perfect-mount model). Odometry slips:
// each step's true motion is lengthened by 3 % and turned by 1 deg per metre, and the prior bounds
// it to twice that plus 2 cm / 0.2 deg. Per world and mode: the final pose's error, ATE without
// alignment, loop closures registered / failed / accepted / refused / wrong (IsWrongLoopClosure
// against the truth), and the calibration of the edges' information: chi2 = e^T C^-1 e of each
// edge's true error e under the registration's own covariance C (unscaled). Were C right, chi2
// would average 6 (its degrees of freedom); 6 / mean is the factor the information is
// over-confident by, the basis of LoopClosureConfig::information_scale. cpu_s_per_scan: the
// process's CPU time in MapBuilder::Add per scan (registrations, graph, re-posing).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pitchlab/mapping/map_builder.hpp"
#include "pitchlab/mapping/trajectory_metrics.hpp"
#include "pitchlab/sensors/scan3d.hpp"
#include "pitchlab/sim/sim_rig.hpp"

namespace {

using namespace pitchlab;
using Vector6d = Eigen::Matrix<double, 6, 1>;

struct Stop {
  double x_m, y_m, yaw_deg;
};

// Office: along the corridor (y in [-1, 1]) 7 m east, turn about, back, and turn to face east
// again where it began. Urban: a 3 m square around the crossroads' centre, ending at the start.
std::vector<Stop> Route(const std::string& world) {
  if (world == "office") {
    std::vector<Stop> r;
    for (int x = -8; x <= -1; ++x) r.push_back({double(x), 0, 0});
    r.push_back({-1, 0, 90});
    for (int x = -1; x >= -8; --x) r.push_back({double(x), 0, 180});
    r.push_back({-8, 0, 270});
    r.push_back({-8, 0, 360});
    return r;
  }
  if (world == "urban") {
    return {{0, 0, 0},     {1.5, 0, 0}, {3, 0, 0},     {3, 0, 90},  {3, 1.5, 90},
            {3, 3, 90},    {3, 3, 180}, {1.5, 3, 180}, {0, 3, 180}, {0, 3, 270},
            {0, 1.5, 270}, {0, 0, 270}, {0, 0, 360}};
  }
  throw std::invalid_argument("loop_closure_eval: no route for world '" + world + "'");
}

std::vector<sensors::Scan3D> Simulate(const std::string& world, bool legacy) {
  sim::SimRigConfig config;
  if (legacy) config.lms200 = sensors::Lms200Config::Legacy();
  sim::SimRig rig(std::string(PITCHLAB_WORLDS_DIR) + "/" + world + ".xml", config);
  std::vector<sensors::Scan3D> scans;
  for (const Stop& s : Route(world)) {
    auto placed = rig.PlaceRobot(s.x_m, s.y_m, s.yaw_deg * M_PI / 180);
    if (!placed) throw std::runtime_error(world + ": " + placed.error().message);
    auto scan = rig.Acquire();
    if (!scan) throw std::runtime_error(world + ": " + scan.error().message);
    scans.push_back(std::move(*scan));
    std::fprintf(stderr, "%s: simulated stop %zu\n", world.c_str(), scans.size() - 1);
  }
  return scans;
}

// The perturbation e = (omega, v) with Z = Exp(e) * T_true (the pose graph's edge convention).
Vector6d EdgeError(const Eigen::Isometry3d& Z, const Eigen::Isometry3d& T_true) {
  const Eigen::Isometry3d E = Z * T_true.inverse();
  const Eigen::AngleAxisd aa(E.rotation());
  Vector6d e;
  e << aa.angle() * aa.axis(), E.translation();
  return e;
}

double Chi2(const mapping::RegistrationResult& r, const Eigen::Isometry3d& T_true) {
  const Vector6d e = EdgeError(r.T_target_source, T_true);
  return e.dot(r.covariance.ldlt().solve(e));
}

nlohmann::json Summary(std::vector<double> v) {
  if (v.empty()) return nullptr;
  std::sort(v.begin(), v.end());
  double sum = 0;
  for (double x : v) sum += x;
  const double mean = sum / v.size();
  return {{"n", v.size()},
          {"mean", mean},
          {"median", v[v.size() / 2]},
          {"max", v.back()},
          {"over_confidence_6_over_mean", 6.0 / mean}};
}

nlohmann::json Run(const std::vector<sensors::Scan3D>& scans, bool loops, double scale) {
  mapping::MapConfig config;
  config.sensor_base = sensors::MountConfig{}.BaseToLaser(0.0).translation().cast<float>();
  config.loop_closure.enabled = loops;
  config.loop_closure.information_scale = scale;
  mapping::MapBuilder builder(config);
  const std::clock_t cpu_start = std::clock();  // one thread: the process's CPU is the builder's
  const Eigen::Isometry3d T_world_map = scans[0].T_world_base;
  std::vector<Eigen::Isometry3d> truth(scans.size());  // T_map_base
  std::vector<double> sequential_chi2, loop_chi2;
  std::size_t merged_last = 0, failed = 0;
  nlohmann::json attempts = nlohmann::json::array();
  for (std::size_t k = 0; k < scans.size(); ++k) {
    truth[k] = T_world_map.inverse() * scans[k].T_world_base;
    std::optional<Eigen::Isometry3d> odometry;
    std::optional<mapping::GuessUncertainty> bound;
    if (k > 0) {  // the true motion since the last merged stop, slipped
      const Eigen::Isometry3d motion = truth[merged_last].inverse() * truth[k];
      const double length = motion.translation().norm();
      Eigen::Isometry3d slipped = motion;
      slipped.translation() *= 1.03;
      slipped.rotate(Eigen::AngleAxisd(length * M_PI / 180, Eigen::Vector3d::UnitZ()));
      odometry = builder.trajectory().back().T_map_base * slipped;
      bound = mapping::GuessUncertainty{2 * 0.03 * length + 0.02, 2 * length + 0.2};
    }
    auto step = builder.Add(mapping::CloudFromScan(scans[k]), odometry, bound);
    if (!step) throw std::runtime_error(step.error().message);
    if (!step->merged) {
      ++failed;
      continue;
    }
    if (k > 0) {
      sequential_chi2.push_back(Chi2(step->registration, truth[merged_last].inverse() * truth[k]));
    }
    for (const mapping::LoopAttempt& a : step->loop_attempts) {
      attempts.push_back({{"scan", k},
                          {"against", a.target_scan_index},
                          {"bound_m", a.candidate.uncertainty_m},
                          {"outcome", mapping::ToString(a.registration.outcome)},
                          {"accepted", a.tested && a.decision.accepted},
                          {"chi2_increase", a.decision.chi2_increase},
                          {"reason", a.registration.reason.substr(0, 160)}});
      if (!a.registration.success) continue;
      loop_chi2.push_back(Chi2(a.registration, truth[a.target_scan_index].inverse() * truth[k]));
    }
    merged_last = k;
  }
  const double cpu_s = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  std::vector<Eigen::Isometry3d> estimate, truth_merged;
  for (const mapping::TrajectoryPose& p : builder.trajectory()) {
    estimate.push_back(p.T_map_base);
    truth_merged.push_back(truth[p.scan_index]);
  }
  std::size_t wrong = 0;
  for (const mapping::LoopClosure& l : builder.accepted_loops()) {
    wrong += mapping::IsWrongLoopClosure(
        l.T_from_to, truth[l.from_scan_index].inverse() * truth[l.to_scan_index]);
  }
  const auto ate = mapping::AbsoluteTrajectoryErrorUnaligned(estimate, truth_merged);
  const mapping::PoseError final_error =
      mapping::ComparePoses(estimate.back(), truth_merged.back());
  const mapping::LoopClosureCounts c = builder.loop_closures();
  return {{"loop_closure", loops},
          {"scans", scans.size()},
          {"not_merged", failed},
          {"cpu_s_per_scan", cpu_s / scans.size()},
          {"final_error_m", final_error.translation_m},
          {"final_error_deg", final_error.rotation_deg},
          {"ate_rmse_m", ate ? ate->rmse_m : -1.0},
          {"ate_max_m", ate ? ate->max_m : -1.0},
          {"loops",
           {{"registered", c.registered},
            {"registration_failed", c.registration_failed},
            {"accepted", c.accepted},
            {"rejected", c.rejected},
            {"wrong", wrong}}},
          {"sequential_edge_chi2", Summary(sequential_chi2)},
          {"loop_edge_chi2", Summary(loop_chi2)},
          {"loop_attempts", attempts}};
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> worlds = {"office", "urban"};
  double scale = mapping::LoopClosureConfig::kEdgeInformationScale;
  bool legacy = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--worlds" && i + 1 < argc) {
      worlds.clear();
      std::stringstream list(argv[++i]);
      for (std::string w; std::getline(list, w, ',');) worlds.push_back(w);
    } else if (a == "--scale" && i + 1 < argc) {
      scale = std::stod(argv[++i]);
    } else if (a == "--legacy-lms200") {
      legacy = true;
    } else {
      std::fprintf(stderr,
                   "usage: loop_closure_eval [--worlds office,urban] [--scale S] "
                   "[--legacy-lms200]\n");
      return 2;
    }
  }
  nlohmann::json out = {{"information_scale", scale}, {"legacy_lms200", legacy}};
  for (const std::string& world : worlds) {
    const std::vector<sensors::Scan3D> scans = Simulate(world, legacy);
    out["worlds"][world] = {Run(scans, false, scale), Run(scans, true, scale)};
    std::cout << out.dump(2) << std::endl;  // progress: each world's result as it comes
  }
  return 0;
}
