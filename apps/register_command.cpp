// `pitchlab register`: align two scans (Algorithm 1) and print the transform and result fields.

#include <cmath>
#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "cloud_input.hpp"
#include "commands.hpp"
#include "pitchlab/mapping/registration.hpp"
#include "pitchlab/sensors/cloud_file.hpp"
#include "pitchlab/mission/registration_json.hpp"

namespace pitchlab::apps {
namespace {

CliArgs RegisterArgs() {
  CliArgs args(
      "register",
      "Aligns SOURCE to TARGET (voxel grid, normals, FPFH, sample-consensus initial\n"
      "alignment, Levenberg-Marquardt ICP) and prints T_target_source, which maps SOURCE's\n"
      "points into TARGET's frame, with its covariance and the settings the clouds resolved\n"
      "to (lengths and gates follow the measured noise and scale: mapping/README.md).\n"
      "Exit 0 when registered, 1 when the registration failed or was ambiguous (the reason\n"
      "is printed), 2 on bad arguments.\n\n" +
          std::string(sensors::CloudFormatsHelp()));
  args.Positionals("SOURCE TARGET", "the cloud to align, and the cloud it is aligned to", 2, 2)
      .Option("prior", "x,y,z,roll,pitch,yaw|files",
              "odometry guess of T_target_source: metres and degrees, or 'files': from the "
              "two files' poses (a 3DTK .pose, a PCD's VIEWPOINT); enables the geometric "
              "constraint around it")
      .Option("prior-error", "metres,degrees",
              "how far the --prior may be off at most; only a prior bounded within the "
              "settings carry_max_m / carry_max_deg may supply what degenerate geometry (a "
              "corridor's axis) leaves unconstrained, else that is a failure")
      .Option("previous", "x,y,z,roll,pitch,yaw",
              "the previous pair's motion (constant velocity), tried when there is no --prior")
      .Option("sensor-origin", "x,y,z", kSensorOriginHelp)
      .Flag("as-recorded", kAsRecordedHelp)
      .Option("config", "FILE.yaml",
              "settings in its 'registration:' section (see mapping/README.md)")
      .Flag("json", "print the result as JSON on stdout");
  return args;
}

Eigen::Isometry3d PoseOption(const CliArgs& args, const std::string& name) {
  const std::vector<double> v = args.GetNumbers(name, 6);
  return mapping::PoseFromXyzRpyDeg(v[0], v[1], v[2], v[3], v[4], v[5]);
}

// --prior files: the motion between the two files' own poses.
Eigen::Isometry3d PriorFromFiles(const sensors::Scan3D& source, const std::string& source_path,
                                 const sensors::Scan3D& target, const std::string& target_path) {
  for (const auto& [scan, path] : {std::pair{&source, &source_path}, {&target, &target_path}}) {
    if (!scan->has_odometry && !scan->has_truth) {
      throw CliError("--prior files: " + *path +
                     " carries no pose (a 3DTK scan's .pose, a PCD's VIEWPOINT)");
    }
  }
  return target.T_world_base.inverse() * source.T_world_base;
}

nlohmann::json StatisticsJson(const mapping::CloudStatistics& s) {
  return {{"points", s.points},
          {"median_range_m", s.median_range_m},
          {"spacing_m", s.spacing_m},
          {"noise_m", s.noise_m}};
}

// The standard deviations the covariance gives each axis: what the scans (or the guess) fix.
nlohmann::json SigmasJson(const mapping::Matrix6d& cov) {
  const double k = 180.0 / 3.14159265358979323846;
  return {{"roll_deg", std::sqrt(cov(0, 0)) * k}, {"pitch_deg", std::sqrt(cov(1, 1)) * k},
          {"yaw_deg", std::sqrt(cov(2, 2)) * k},  {"x_m", std::sqrt(cov(3, 3))},
          {"y_m", std::sqrt(cov(4, 4))},          {"z_m", std::sqrt(cov(5, 5))}};
}

nlohmann::json ResultJson(const mapping::RegistrationResult& r) {
  nlohmann::json matrix = nlohmann::json::array();
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) matrix.push_back(r.T_target_source.matrix()(row, col));
  }
  const mapping::RegistrationConfig& c = r.settings;
  nlohmann::json out = {{"T_target_source", matrix},
                        {"success", r.success},
                        {"reason", r.reason},
                        {"path", mapping::ToString(r.path)},
                        {"fitness_m2", r.fitness_m2},
                        {"rmse_m", r.rmse_m},
                        {"inlier_ratio", r.inlier_ratio},
                        {"degeneracy", r.degeneracy},
                        {"sac_inliers", r.sac_inliers},
                        {"iterations", r.iterations},
                        {"information", mission::Matrix6Json(r.information)},
                        {"sigma", SigmasJson(r.covariance)},
                        {"statistics",
                         {{"source", StatisticsJson(r.source_statistics)},
                          {"target", StatisticsJson(r.target_statistics)}}},
                        {"settings_used",
                         {{"length_scale", c.length_scale},
                          {"icp_voxel_m", c.icp_voxel_m},
                          {"feature_voxel_m", c.feature_voxel_m},
                          {"inlier_distance_m", c.inlier_distance_m},
                          {"max_rmse_m", c.max_rmse_m},
                          {"free_space_margin_m", c.free_space_margin_m},
                          {"icp_max_distance_m", c.icp_max_distance_m},
                          {"icp_min_distance_m", c.icp_min_distance_m},
                          {"constraint_translation_m", c.constraint_translation_m}}},
                        {"timings_s", mission::StageTimingsJson(r.timings)}};
  // Outcome, covariance, noise, length scale: as run stops say.
  out.update(mission::ObservabilityJson(r));
  return out;
}

}  // namespace

int RunRegister(int argc, char** argv) {
  CliArgs args = RegisterArgs();
  if (!args.Parse(argc, argv)) return 0;
  const std::string source_path = args.positionals()[0], target_path = args.positionals()[1];
  mapping::RegistrationConfig config;
  if (args.Has("config")) config = mapping::LoadRegistrationConfig(args.Get("config"));
  const std::optional<Eigen::Vector3d> origin = SensorOriginOption(args);
  mapping::RegistrationPrior prior;
  const bool prior_from_files = args.Has("prior") && args.Get("prior") == "files";
  if (args.Has("prior") && !prior_from_files) prior.odometry = PoseOption(args, "prior");
  if (const auto e = PriorErrorOption(args)) {
    if (!args.Has("prior")) throw CliError("--prior-error bounds a --prior; give one");
    prior.odometry_uncertainty = mapping::GuessUncertainty{e->first, e->second};
  }
  if (args.Has("previous")) prior.previous_motion = PoseOption(args, "previous");

  const bool set_lines_right = !args.Flagged("as-recorded");
  nlohmann::json line_pitch = {{"source", nullptr}, {"target", nullptr}};
  const sensors::Scan3D source =
      LoadInputCloud(source_path, origin, set_lines_right, &line_pitch["source"]);
  const sensors::Scan3D target =
      LoadInputCloud(target_path, origin, set_lines_right, &line_pitch["target"]);
  if (prior_from_files) prior.odometry = PriorFromFiles(source, source_path, target, target_path);
  prior.source_sensor = source.sensor_origin->cast<float>();  // LoadInputCloud always sets it
  prior.target_sensor = target.sensor_origin->cast<float>();
  Result<mapping::RegistrationResult> r = mapping::Register(
      mapping::CloudFromScan(target), mapping::CloudFromScan(source), prior, config);
  if (!r) throw std::runtime_error(r.error().message);

  nlohmann::json out = ResultJson(*r);
  out["source"] = source_path;
  out["target"] = target_path;
  out["line_pitch"] = line_pitch;
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
  std::printf("%s: %s\nT_target_source =\n",
              r->success ? "registered"
                         : (r->outcome == mapping::RegistrationOutcome::kAmbiguous ? "AMBIGUOUS"
                                                                                   : "FAILED"),
              r->reason.c_str());
  for (int row = 0; row < 4; ++row) {
    std::printf("  %10.6f %10.6f %10.6f %10.6f\n", M(row, 0), M(row, 1), M(row, 2), M(row, 3));
  }
  std::printf("path %s, fitness %.3g m^2, rmse %.4f m, inliers %.1f %%, %d ICP iterations\n",
              mapping::ToString(r->path), r->fitness_m2, r->rmse_m, 100 * r->inlier_ratio,
              r->iterations);
  const nlohmann::json& sd = out["sigma"];
  std::printf(
      "1-sigma: roll %.2g, pitch %.2g, yaw %.2g deg; x %.2g, y %.2g, z %.2g m (source noise "
      "%.2g m, target %.2g m, length scale %g)\n",
      sd["roll_deg"].get<double>(), sd["pitch_deg"].get<double>(), sd["yaw_deg"].get<double>(),
      sd["x_m"].get<double>(), sd["y_m"].get<double>(), sd["z_m"].get<double>(),
      r->source_statistics.noise_m, r->target_statistics.noise_m, r->settings.length_scale);
  const mapping::RegistrationResult::FreeSpace& fs = r->free_space;
  std::printf(
      "free space: %.2g %% of %d source points the target's scan could judge lie where its beams "
      "passed, %.2g %% of %d target points in the source's (a pose is refused above %g %%)\n",
      100 * fs.source_violating, fs.source_judged, 100 * fs.target_violating, fs.target_judged,
      100 * mapping::kChangedViewShare);
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
