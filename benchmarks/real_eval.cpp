// real_eval: registration held to real scans with reference poses. For every consecutive pair of
// scans in a folder (3DTK scanNNN.3d with scanNNN.pose as odometry and slam6d's scanNNN.frames*
// as the reference), both ways round, with the odometry prior (and an error bound) and without
// any: the outcome, the error against the reference, and the fit at our pose and at the
// reference's (the share of the source's points within 5 cm of the target, and their
// point-to-plane RMS, at full resolution), with the CPU time of the registering thread. Prints
// JSON. Every pair that registered with the prior is registered again from wrong priors and the
// wrong way round (real_wrong_priors.hpp): no success may land away from the pose. Then the map
// check (real_map_check.hpp) of all the scans at the reference poses and at ours (each scan
// registered into the one before, with the odometry prior, chained).
//
//   real_eval DIR [--prior-error m,deg] [--config FILE.yaml]

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <regex>
#include <string>
#include <unordered_map>
#include <vector>

#include <time.h>

#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include "pitchlab/mapping/line_pitch.hpp"
#include "pitchlab/mapping/registration.hpp"
#include "pitchlab/mission/registration_json.hpp"
#include "pitchlab/sensors/cloud_file.hpp"
#include "real_map_check.hpp"
#include "real_wrong_priors.hpp"

namespace {

using namespace pitchlab;
using json = nlohmann::json;
namespace fs = std::filesystem;

// The fit is judged within this distance (SOURCES.md's figures: 74.6 % at slam6d's pose) [m].
constexpr double kFitDistance_m = 0.05;

double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Points bucketed in cubes of kFitDistance_m: every point within it of a query lies in the 27
// cubes around the query's.
class Grid {
 public:
  explicit Grid(const mapping::PointCloud& cloud) : cloud_(cloud) {
    for (std::size_t i = 0; i < cloud.size(); ++i) cells_[Key(Cell(cloud[i]))].push_back(i);
  }
  // Indices of points within kFitDistance_m of q.
  std::vector<std::size_t> Near(const Eigen::Vector3f& q) const {
    std::vector<std::size_t> out;
    const Eigen::Vector3i c = Cell(q);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          auto it = cells_.find(Key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (std::size_t j : it->second) {
            if ((cloud_[j] - q).squaredNorm() <= kFitDistance_m * kFitDistance_m) out.push_back(j);
          }
        }
    return out;
  }

 private:
  static Eigen::Vector3i Cell(const Eigen::Vector3f& p) {
    return (p / static_cast<float>(kFitDistance_m)).array().floor().cast<int>();
  }
  static std::int64_t Key(const Eigen::Vector3i& c) {
    return (static_cast<std::int64_t>(c.x() + (1 << 20)) << 42) |
           (static_cast<std::int64_t>(c.y() + (1 << 20)) << 21) | (c.z() + (1 << 20));
  }
  const mapping::PointCloud& cloud_;
  std::unordered_map<std::int64_t, std::vector<std::size_t>> cells_;
};

struct Fit {
  double within = 0;    // share of source points within kFitDistance_m of the target [1]
  double rms_m = 0;     // their point-to-plane RMS against the target's local planes [m]
};

// The fit of `source` moved by T into `target`, every point counted (full resolution).
Fit FitAt(const Grid& grid, const mapping::PointCloud& target, const mapping::PointCloud& source,
          const Eigen::Isometry3d& T) {
  const Eigen::Isometry3f Tf = T.cast<float>();
  std::size_t within = 0, planes = 0;
  double sq = 0;
  for (const Eigen::Vector3f& p : source) {
    const Eigen::Vector3f q = Tf * p;
    const std::vector<std::size_t> near = grid.Near(q);
    if (near.empty()) continue;
    ++within;
    if (near.size() < 5) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (std::size_t j : near) mean += target[j].cast<double>();
    mean /= static_cast<double>(near.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (std::size_t j : near) {
      const Eigen::Vector3d d = target[j].cast<double>() - mean;
      cov += d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(cov);
    const double r = eig.eigenvectors().col(0).dot(q.cast<double>() - mean);
    sq += r * r;
    ++planes;
  }
  Fit f;
  f.within = source.empty() ? 0 : static_cast<double>(within) / source.size();
  f.rms_m = planes ? std::sqrt(sq / planes) : 0;
  return f;
}

struct Scan {
  std::string path;
  sensors::Scan3D scan;
  mapping::PointCloud cloud;
  Eigen::Isometry3d reference;  // slam6d's registered pose
  mapping::LinePitch line_pitch;  // what setting its lines right did
  double line_pitch_cpu_s = 0;    // and its CPU time [s]
};

// Where the scan's sensor stood in its own frame (3DTK's: the origin).
Eigen::Vector3f SensorOf(const Scan& s) {
  return s.scan.sensor_origin.value_or(Eigen::Vector3d::Zero()).cast<float>();
}

Scan Load(const fs::path& path) {
  Scan s;
  s.path = path.string();
  Result<sensors::Scan3D> scan = sensors::ReadCloudFile(s.path);
  if (!scan) throw std::runtime_error(scan.error().message);
  s.scan = *scan;
  s.cloud = mapping::CloudFromScan(s.scan);
  // Each nodding line set right by the floor it crossed, as the commands read real scans.
  const double cpu = ThreadCpuSeconds();
  s.line_pitch = mapping::RectifyLinePitch(s.cloud, SensorOf(s));
  s.line_pitch_cpu_s = ThreadCpuSeconds() - cpu;
  // The reference: scanNNN.frames, or any scanNNN.frames.* beside it.
  const std::string stem = path.stem().string();
  std::vector<fs::path> frames;
  for (const auto& e : fs::directory_iterator(path.parent_path())) {
    const std::string name = e.path().filename().string();
    if (name.rfind(stem + ".frames", 0) == 0) frames.push_back(e.path());
  }
  if (frames.empty()) throw std::runtime_error(s.path + ": no " + stem + ".frames* beside it");
  std::sort(frames.begin(), frames.end());
  Result<Eigen::Isometry3d> ref = sensors::Read3dtkFrames(frames.front().string());
  if (!ref) throw std::runtime_error(ref.error().message);
  s.reference = *ref;
  return s;
}

json Run(const Scan& target, const Scan& source, const Grid& grid, bool with_prior,
         const mapping::GuessUncertainty& bound, const mapping::RegistrationConfig& config,
         Eigen::Isometry3d& T_target_source) {
  mapping::RegistrationPrior prior;
  prior.source_sensor = SensorOf(source);
  prior.target_sensor = SensorOf(target);
  if (with_prior) {
    prior.odometry = target.scan.T_world_base.inverse() * source.scan.T_world_base;
    prior.odometry_uncertainty = bound;
  }
  const double cpu = ThreadCpuSeconds();
  Result<mapping::RegistrationResult> r =
      mapping::Register(target.cloud, source.cloud, prior, config);
  const double cpu_s = ThreadCpuSeconds() - cpu;
  if (!r) return {{"error", r.error().message}};
  T_target_source = r->T_target_source;
  const Eigen::Isometry3d reference = target.reference.inverse() * source.reference;
  const mapping::PoseError e = mapping::ComparePoses(r->T_target_source, reference);
  const Fit ours = FitAt(grid, target.cloud, source.cloud, r->T_target_source);
  const Fit ref = FitAt(grid, target.cloud, source.cloud, reference);
  json out = {{"prior", with_prior},
              {"success", r->success},
              {"outcome", mapping::ToString(r->outcome)},
              {"path", mapping::ToString(r->path)},
              {"reason", r->reason},
              {"error_vs_reference", {{"rotation_deg", e.rotation_deg},
                                      {"translation_m", e.translation_m}}},
              {"within_5cm", {{"ours", ours.within}, {"reference", ref.within}}},
              {"point_to_plane_rms_m", {{"ours", ours.rms_m}, {"reference", ref.rms_m}}},
              {"inlier_rmse_m", r->rmse_m},
              {"noise_m", {{"source", r->source_statistics.noise_m},
                           {"target", r->target_statistics.noise_m}}},
              {"length_scale", r->settings.length_scale},
              // At our pose: how much of each scan's judged view the other puts where its beams
              // passed (a real scene changes between scans; above 5 % a pose is refused).
              {"free_space", mission::FreeSpaceJson(r->free_space)},
              {"cpu_s", cpu_s}};
  if (with_prior) {
    const mapping::PoseError o = mapping::ComparePoses(*prior.odometry, reference);
    out["odometry_vs_reference"] = {{"rotation_deg", o.rotation_deg},
                                    {"translation_m", o.translation_m}};
    out["within_5cm"]["odometry"] = FitAt(grid, target.cloud, source.cloud, *prior.odometry).within;
  }
  return out;
}

// Whether the servo's pitch errors repeat from scan to scan, so that a table taken once could
// correct them: the lines two scans share (the same recorded pitch, within the line gap that
// tells lines apart, and the same interlaced sweep) and how their corrections compare.
// `table_leaves_deg` is what scan a's corrections, applied to scan b, would leave of b's error (RMS
// of the difference), against `rms_b_deg` with no correction at all.
json LinePitchRepeat(const mapping::LinePitch& a, const mapping::LinePitch& b) {
  const double gap = mapping::LinePitchConfig{}.line_gap_rad;
  std::vector<std::pair<double, double>> shared;
  for (const mapping::LineCorrection& ca : a.line_corrections) {
    for (const mapping::LineCorrection& cb : b.line_corrections) {
      if (ca.sweep == cb.sweep && std::abs(ca.pitch_rad - cb.pitch_rad) <= gap) {
        shared.emplace_back(ca.correction_rad, cb.correction_rad);
        break;
      }
    }
  }
  if (shared.size() < 3) return {{"shared_lines", shared.size()}};
  const double n = static_cast<double>(shared.size());
  double ma = 0, mb = 0;
  for (const auto& [x, y] : shared) ma += x / n, mb += y / n;
  double saa = 0, sbb = 0, sab = 0, a2 = 0, b2 = 0, d2 = 0;
  for (const auto& [x, y] : shared) {
    saa += (x - ma) * (x - ma), sbb += (y - mb) * (y - mb), sab += (x - ma) * (y - mb);
    a2 += x * x, b2 += y * y, d2 += (x - y) * (x - y);
  }
  constexpr double kToDeg = 180 / 3.14159265358979323846;
  return {{"shared_lines", shared.size()},
          {"correlation", sab / std::sqrt(saa * sbb)},
          {"rms_a_deg", std::sqrt(a2 / n) * kToDeg},
          {"rms_b_deg", std::sqrt(b2 / n) * kToDeg},
          {"table_leaves_deg", std::sqrt(d2 / n) * kToDeg}};
}

}  // namespace

int main(int argc, char** argv) {
  std::string dir;
  mapping::GuessUncertainty bound{0.1, 1.0};  // wheel odometry over 1-2 m: SOURCES.md 1.7 cm / 0.7 deg
  mapping::RegistrationConfig config;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--help") {
        std::puts("real_eval DIR [--prior-error m,deg] [--config FILE.yaml]");
        return 0;
      } else if (a == "--prior-error" && i + 1 < argc) {
        if (std::sscanf(argv[++i], "%lf,%lf", &bound.translation_m, &bound.rotation_deg) != 2) {
          throw std::invalid_argument("--prior-error wants metres,degrees");
        }
      } else if (a == "--config" && i + 1 < argc) {
        config = mapping::LoadRegistrationConfig(argv[++i]);
      } else if (dir.empty() && a.rfind("--", 0) != 0) {
        dir = a;
      } else {
        throw std::invalid_argument("unknown argument " + a);
      }
    }
    if (dir.empty()) throw std::invalid_argument("give the folder of scans");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "real_eval: %s\n", e.what());
    return 2;
  }
  try {
    std::vector<fs::path> paths;
    const std::regex scan_name(R"(scan\d+\.3d)");
    for (const auto& e : fs::directory_iterator(dir)) {
      if (std::regex_match(e.path().filename().string(), scan_name)) paths.push_back(e.path());
    }
    std::sort(paths.begin(), paths.end());
    if (paths.size() < 2) throw std::runtime_error(dir + ": fewer than two scanNNN.3d");
    std::vector<Scan> scans;
    for (const fs::path& p : paths) scans.push_back(Load(p));
    json pairs = json::array();
    std::vector<double> cpu;
    // Our pose of each scan in the first one's frame (with the prior, into the scan before).
    std::vector<Eigen::Isometry3d> ours{Eigen::Isometry3d::Identity()};
    bool chained = true;
    int runs = 0, successes = 0, within_target = 0, false_successes = 0;
    json wrong_priors = json::array();
    int wrong_runs = 0, wrong_off_reference = 0, wrong_off_ours = 0;
    for (std::size_t k = 0; k + 1 < scans.size(); ++k) {
      for (const auto& [t, s] : {std::pair{&scans[k], &scans[k + 1]}, {&scans[k + 1], &scans[k]}}) {
        const Grid grid(t->cloud);
        for (const bool with_prior : {true, false}) {
          std::fprintf(stderr, "  %s -> %s, %s\n", s->path.c_str(), t->path.c_str(),
                       with_prior ? "odometry prior" : "no prior");
          Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
          json r = Run(*t, *s, grid, with_prior, bound, config, T);
          if (with_prior && s == &scans[k + 1]) {
            chained = chained && r.value("success", false);
            ours.push_back(ours.back() * T);
          }
          if (with_prior && r.value("success", false)) {
            std::fprintf(stderr, "  %s -> %s, wrong priors\n", s->path.c_str(), t->path.c_str());
            benchmarks::WrongPriorPair pair{&t->cloud,
                                            &s->cloud,
                                            SensorOf(*t),
                                            SensorOf(*s),
                                            t->reference.inverse() * s->reference,
                                            T};
            json w = benchmarks::CheckWrongPriors(pair, config);
            wrong_runs += w["runs"].get<int>();
            wrong_off_reference += w["successes_off_the_reference"].get<int>();
            wrong_off_ours += w["successes_off_ours"].get<int>();
            w["source"] = s->path;
            w["target"] = t->path;
            wrong_priors.push_back(std::move(w));
          }
          r["source"] = s->path;
          r["target"] = t->path;
          if (!r.contains("error")) {
            ++runs;
            const double deg = r["error_vs_reference"]["rotation_deg"];
            const double m = r["error_vs_reference"]["translation_m"];
            const bool ok = r["success"];
            successes += ok;
            // The reference is good to 0.5-1 deg (SOURCES.md): 1 deg / 5 cm is "the same pose".
            within_target += ok && deg <= 1.0 && m <= 0.05;
            false_successes += ok && (deg > 1.0 || m > 0.05);
            cpu.push_back(r["cpu_s"]);
          }
          pairs.push_back(r);
        }
      }
    }
    std::sort(cpu.begin(), cpu.end());
    std::vector<benchmarks::PosedCloud> at_reference, at_ours;
    for (std::size_t k = 0; k < scans.size(); ++k) {
      const Eigen::Vector3f sensor = SensorOf(scans[k]);
      at_reference.push_back(
          {&scans[k].cloud, sensor, scans[0].reference.inverse() * scans[k].reference});
      at_ours.push_back({&scans[k].cloud, sensor, ours[k]});
    }
    std::fprintf(stderr, "  map check\n");
    json map_check = {{"at_reference", benchmarks::CheckMap(at_reference)}};
    // Each scan alone: how flat the data's own floor is, whatever the poses.
    for (const benchmarks::PosedCloud& one : at_reference) {
      map_check["each_scan_alone"].push_back(benchmarks::CheckMap({one})["floor"]);
    }
    if (chained) {
      map_check["at_ours"] = benchmarks::CheckMap(at_ours);
    } else {
      map_check["at_ours"] = "not built: a registration with the prior failed";
    }
    json line_pitch = json::array();
    for (const Scan& s : scans) {
      json j = mission::LinePitchJson(s.line_pitch);
      j["scan"] = s.path;
      j["cpu_s"] = s.line_pitch_cpu_s;
      line_pitch.push_back(j);
    }
    json repeat = json::array();
    for (std::size_t k = 1; k < scans.size(); ++k) {
      json r = LinePitchRepeat(scans[k - 1].line_pitch, scans[k].line_pitch);
      r["scans"] = {scans[k - 1].path, scans[k].path};
      repeat.push_back(r);
    }
    json out = {{"folder", dir},
                {"line_pitch", line_pitch},
                {"line_pitch_repeat", repeat},
                {"prior_error", {bound.translation_m, bound.rotation_deg}},
                {"runs", runs},
                {"successes", successes},
                {"within_1deg_5cm_of_reference", within_target},
                {"successes_off_the_reference", false_successes},
                {"cpu_s",
                 {{"median", cpu.empty() ? 0 : cpu[cpu.size() / 2]},
                  {"max", cpu.empty() ? 0 : cpu.back()}}},
                {"map", map_check},
                {"wrong_priors",
                 {{"runs", wrong_runs},
                  {"successes_off_the_reference", wrong_off_reference},
                  {"successes_off_ours", wrong_off_ours},
                  {"pairs", wrong_priors}}},
                {"runs_detail", pairs}};
    std::cout << out.dump(2) << "\n";
  } catch (const std::exception& e) {
    std::fprintf(stderr, "real_eval: %s\n", e.what());
    return 1;
  }
  return 0;
}
