// `pitchlab register`: align two scans (Algorithm 1) and print the transform and result fields.

#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "commands.hpp"
#include "pitchlab/mapping/registration.hpp"
#include "pitchlab/sensors/scan_pcd.hpp"
#include "registration_json.hpp"

namespace pitchlab::apps {
namespace {

CliArgs RegisterArgs() {
  CliArgs args(
      "register",
      "Aligns SOURCE to TARGET (voxel grid, normals, FPFH, sample-consensus initial\n"
      "alignment, Levenberg-Marquardt ICP) and prints T_target_source, which maps SOURCE's\n"
      "points into TARGET's frame. Exit 0 when registered, 1 when the registration\n"
      "failed (the reason is printed), 2 on bad arguments.");
  args.Positionals("SOURCE.pcd TARGET.pcd", "the scan to align, and the scan it is aligned to", 2,
                   2)
      .Option("prior", "x,y,z,roll,pitch,yaw",
              "odometry guess of T_target_source: metres and degrees; enables the geometric "
              "constraint around it")
      .Option("prior-error", "metres,degrees",
              "how far the --prior may be off at most; only a prior bounded within the "
              "settings carry_max_m / carry_max_deg may supply what degenerate geometry (a "
              "corridor's axis) leaves unconstrained, else that is a failure")
      .Option("previous", "x,y,z,roll,pitch,yaw",
              "the previous pair's motion, used when the initial alignment fails (constant "
              "velocity)")
      .Option("config", "FILE.yaml",
              "settings in its 'registration:' section (see mapping/README.md)")
      .Flag("json", "print the result as JSON on stdout");
  return args;
}

sensors::Scan3D ReadScan(const std::string& path) {
  Result<sensors::Scan3D> scan = sensors::ReadScanPcd(path);
  if (!scan) throw std::runtime_error(scan.error().message);
  return *scan;
}

Eigen::Isometry3d PoseOption(const CliArgs& args, const std::string& name) {
  const std::vector<double> v = args.GetNumbers(name, 6);
  return mapping::PoseFromXyzRpyDeg(v[0], v[1], v[2], v[3], v[4], v[5]);
}

nlohmann::json ResultJson(const mapping::RegistrationResult& r) {
  nlohmann::json matrix = nlohmann::json::array();
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) matrix.push_back(r.T_target_source.matrix()(row, col));
  }
  return {{"T_target_source", matrix},
          {"success", r.success},
          {"reason", r.reason},
          {"path", mapping::ToString(r.path)},
          {"fitness_m2", r.fitness_m2},
          {"rmse_m", r.rmse_m},
          {"inlier_ratio", r.inlier_ratio},
          {"degeneracy", r.degeneracy},
          {"sac_inliers", r.sac_inliers},
          {"iterations", r.iterations},
          {"timings_s", StageTimingsJson(r.timings)}};
}

}  // namespace

int RunRegister(int argc, char** argv) {
  CliArgs args = RegisterArgs();
  if (!args.Parse(argc, argv)) return 0;
  const std::string source_path = args.positionals()[0], target_path = args.positionals()[1];
  mapping::RegistrationConfig config;
  if (args.Has("config")) config = mapping::LoadRegistrationConfig(args.Get("config"));
  mapping::RegistrationPrior prior;
  if (args.Has("prior")) prior.odometry = PoseOption(args, "prior");
  if (args.Has("prior-error")) {
    const std::vector<double> e = args.GetNumbers("prior-error", 2);
    prior.odometry_uncertainty = mapping::GuessUncertainty{e[0], e[1]};
  }
  if (args.Has("previous")) prior.previous_motion = PoseOption(args, "previous");

  const sensors::Scan3D source = ReadScan(source_path), target = ReadScan(target_path);
  Result<mapping::RegistrationResult> r = mapping::Register(
      mapping::CloudFromScan(target), mapping::CloudFromScan(source), prior, config);
  if (!r) throw std::runtime_error(r.error().message);

  nlohmann::json out = ResultJson(*r);
  out["source"] = source_path;
  out["target"] = target_path;
  if (source.has_truth && target.has_truth) {  // simulated scans carry their ground truth
    const Eigen::Isometry3d truth = target.T_world_base.inverse() * source.T_world_base;
    const mapping::PoseError e = mapping::ComparePoses(r->T_target_source, truth);
    out["ground_truth_error"] = {{"rotation_deg", e.rotation_deg},
                                 {"translation_m", e.translation_m}};
  }
  if (args.Flagged("json")) {
    std::cout << out.dump(2) << "\n";
    return r->success ? 0 : 1;
  }
  const Eigen::Matrix4d& M = r->T_target_source.matrix();
  std::printf("%s: %s\nT_target_source =\n", r->success ? "registered" : "FAILED",
              r->reason.c_str());
  for (int row = 0; row < 4; ++row) {
    std::printf("  %10.6f %10.6f %10.6f %10.6f\n", M(row, 0), M(row, 1), M(row, 2), M(row, 3));
  }
  std::printf("path %s, fitness %.3g m^2, rmse %.4f m, inliers %.1f %%, %d ICP iterations\n",
              mapping::ToString(r->path), r->fitness_m2, r->rmse_m, 100 * r->inlier_ratio,
              r->iterations);
  const mapping::StageTimings& t = r->timings;
  std::printf(
      "time %.3f s: voxel %.3f, normals %.3f, features %.3f, initial alignment %.3f, "
      "icp %.3f\n",
      t.total_s, t.voxel_s, t.normals_s, t.features_s, t.initial_alignment_s, t.icp_s);
  if (out.contains("ground_truth_error")) {
    std::printf("against ground truth: %.3f deg, %.4f m\n",
                out["ground_truth_error"]["rotation_deg"].get<double>(),
                out["ground_truth_error"]["translation_m"].get<double>());
  }
  return r->success ? 0 : 1;
}

}  // namespace pitchlab::apps
