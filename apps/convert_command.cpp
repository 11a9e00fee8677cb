// `pitchlab convert`: a point cloud in any format pitchlab reads, written as pitchlab's binary PCD
// (points, pose, and where the sensor stood), so every other command and tool can open it.

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "cli_args.hpp"
#include "cloud_input.hpp"
#include "commands.hpp"
#include "pitchlab/sensors/cloud_file.hpp"
#include "pitchlab/sensors/scan_pcd.hpp"

namespace pitchlab::apps {
namespace {

namespace fs = std::filesystem;

CliArgs ConvertArgs() {
  CliArgs args("convert",
               std::string("Reads a point cloud and writes it as pitchlab's binary PCD (points in\n"
                           "REP-103 metres, VIEWPOINT = the cloud's pose, the sensor origin in a\n"
                           "header comment). Formats, by extension (case-insensitive):\n") +
                   sensors::CloudFormatsHelp() +
                   "Exit 0 when written, 1 for an input that cannot be read (nothing is\n"
                   "written), 2 on bad arguments.");
  args.Positionals("IN", "the cloud to convert", 1, 1)
      .Option("out", "OUT.pcd", "where to write (refused when it exists: give a new name)")
      .Option("sensor-origin", "x,y,z", kSensorOriginHelp)
      .Option("pose-from", "FILE",
              "take the pose from a 3DTK .pose (odometry) or a slam6d .frames file (its last, "
              "registered pose) instead of the input's");
  return args;
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

enum class PoseFile { kPose, kFrames };

// What --pose-from names, judged by its name alone (before anything is read): CliError otherwise.
PoseFile PoseFileKind(const std::string& path) {
  const std::string name = Lower(fs::path(path).filename().string());
  if (name.find(".frames") != std::string::npos) return PoseFile::kFrames;
  if (fs::path(name).extension() == ".pose") return PoseFile::kPose;
  throw CliError("--pose-from '" + path + "': expected a 3DTK .pose or a slam6d .frames file");
}

// `pose_label`: what the pose is ("odometry", "from scan001.frames", ...).
void PrintSummary(const sensors::Scan3D& scan, const std::string& out,
                  const std::string& pose_label) {
  const Eigen::Vector3d t = scan.T_world_base.translation();
  const Eigen::Matrix3d R = scan.T_world_base.rotation();
  const double yaw_deg = std::atan2(R(1, 0), R(0, 0)) * 180.0 / M_PI;
  const Eigen::Vector3d o = scan.sensor_origin.value_or(Eigen::Vector3d::Zero());
  std::printf(
      "wrote %s: %zu points, %zu no-returns; pose (%s) %.3f %.3f %.3f m, yaw %.2f deg; "
      "sensor origin %.3f %.3f %.3f m\n",
      out.c_str(), scan.points.size(), scan.no_returns, pose_label.c_str(), t.x(), t.y(), t.z(),
      yaw_deg, o.x(), o.y(), o.z());
}

}  // namespace

int RunConvert(int argc, char** argv) {
  CliArgs args = ConvertArgs();
  if (!args.Parse(argc, argv)) return 0;
  const std::string in = args.positionals()[0];
  if (!args.Has("out")) throw CliError("'convert' needs --out OUT.pcd");
  const std::string out = args.Get("out");
  if (Lower(fs::path(out).extension().string()) != ".pcd") {
    throw CliError("--out '" + out + "': convert writes PCD; give a name ending in .pcd");
  }
  const std::optional<Eigen::Vector3d> origin = SensorOriginOption(args);
  std::optional<PoseFile> pose_kind;
  if (args.Has("pose-from")) pose_kind = PoseFileKind(args.Get("pose-from"));
  if (fs::exists(out)) {
    throw std::runtime_error("output '" + out + "' already exists; give a new --out");
  }

  sensors::Scan3D scan = LoadInputCloud(in, origin);
  if (pose_kind) {
    const std::string pose_path = args.Get("pose-from");
    const Result<Eigen::Isometry3d> pose = *pose_kind == PoseFile::kPose
                                               ? sensors::Read3dtkPose(pose_path)
                                               : sensors::Read3dtkFrames(pose_path);
    if (!pose) throw std::runtime_error(pose.error().message);
    scan.T_world_base = *pose;
    scan.has_truth = false;  // slam6d's registered pose is a reference, not ground truth
    scan.has_odometry = *pose_kind == PoseFile::kPose;
  }
  if (const Result<void> written = sensors::WriteScanPcd(scan, out); !written) {
    throw std::runtime_error(written.error().message);
  }
  const char* kind = scan.has_truth ? "truth" : scan.has_odometry ? "odometry" : "unknown";
  PrintSummary(scan, out, pose_kind ? "from " + args.Get("pose-from") : std::string(kind));
  return 0;
}

}  // namespace pitchlab::apps
