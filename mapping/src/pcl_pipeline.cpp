#include "pcl_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>

#include <pcl/features/fpfh.h>
#include <pcl/features/narf_descriptor.h>
#include <pcl/features/normal_3d.h>
#include <pcl/features/range_image_border_extractor.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/keypoints/narf_keypoint.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/range_image/range_image.h>
#include <pcl/registration/ia_ransac.h>
#include <pcl/registration/icp_nl.h>
#include <pcl/search/kdtree.h>

namespace pitchlab::mapping {
namespace {

using CloudXyz = pcl::PointCloud<pcl::PointXYZ>;
constexpr float kDegToRad = 3.14159265358979f / 180.0f;

CloudXyz::Ptr ToPcl(const PointCloud& cloud) {
  CloudXyz::Ptr out(new CloudXyz);
  out->reserve(cloud.size());
  for (const Eigen::Vector3f& p : cloud) out->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  return out;
}

double Since(std::chrono::steady_clock::time_point& t) {
  const auto now = std::chrono::steady_clock::now();
  const double s = std::chrono::duration<double>(now - t).count();
  t = now;
  return s;
}

// SAC-IA on any feature type: samples 3 points at least min_sample_distance apart, picks among the
// k most similar features, scores the full source (PCL's Algorithm of Rusu et al. 2009).
template <typename Feature>
PclAlignment RunSacIa(const CloudXyz::Ptr& target, const CloudXyz::Ptr& source,
                      const typename pcl::PointCloud<Feature>::Ptr& target_features,
                      const typename pcl::PointCloud<Feature>::Ptr& source_features,
                      const RegistrationConfig& config, PclAlignment out) {
  pcl::SampleConsensusInitialAlignment<pcl::PointXYZ, pcl::PointXYZ, Feature> sac;
  sac.setInputSource(source);
  sac.setSourceFeatures(source_features);
  sac.setInputTarget(target);
  sac.setTargetFeatures(target_features);
  sac.setMinSampleDistance(static_cast<float>(2.0 * config.feature_voxel_m));
  sac.setMaxCorrespondenceDistance(config.sac_inlier_m);
  sac.setMaximumIterations(config.sac_iterations);
  CloudXyz aligned;
  // SAC-IA samples with std::rand: seeded, so the same input gives the same output.
  std::srand(20120917);
  sac.align(aligned);
  out.found = sac.hasConverged();
  out.T_target_source.matrix() = sac.getFinalTransformation().template cast<double>();
  out.correspondences = static_cast<int>(source->size());
  return out;
}

pcl::PointCloud<pcl::Normal>::Ptr Normals(const CloudXyz::Ptr& cloud, double radius_m) {
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
  ne.setInputCloud(cloud);
  ne.setSearchMethod(
      pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
  ne.setRadiusSearch(radius_m);
  ne.setViewPoint(0.1f, 0.0f, 0.55f);
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  ne.compute(*normals);
  return normals;
}

// NARF keypoints and descriptors (Steder et al. 2011) on a spherical range image of `cloud` seen
// from the laser. The range image wants the dense scan (a pixel per beam): the LMS200 steps 0.5 deg
// in azimuth and the pitch unit about as much, so the image has the scan's own resolution; on a
// 0.3 m voxel cloud almost every pixel would be a border. Unseen pixels (outside the pitch sweep,
// behind the robot) stay unobserved: set to far range they would put borders, and so keypoints,
// along the edges of the field of view, which move with the robot.
void Narf(const CloudXyz::Ptr& cloud, const RegistrationConfig& config, CloudXyz::Ptr& keypoints,
          pcl::PointCloud<pcl::Narf36>::Ptr& descriptors) {
  pcl::RangeImage range_image;
  Eigen::Affine3f sensor = Eigen::Affine3f::Identity();
  sensor.translation() = Eigen::Vector3f(0.1f, 0.0f, 0.55f);
  const float resolution = static_cast<float>(config.narf_angular_resolution_deg) * kDegToRad;
  range_image.createFromPointCloud(*cloud, resolution, 360.0f * kDegToRad, 180.0f * kDegToRad,
                                   sensor, pcl::RangeImage::LASER_FRAME,
                                   static_cast<float>(config.narf_noise_level_m), 0.0f, 1);
  pcl::RangeImageBorderExtractor border_extractor;
  pcl::NarfKeypoint detector(&border_extractor);
  detector.setRangeImage(&range_image);
  detector.getParameters().support_size = static_cast<float>(config.narf_support_m);
  detector.getParameters().add_points_on_straight_edges = true;  // else a few dozen per scan
  detector.getParameters().distance_for_additional_points = 0.5f;
  pcl::PointCloud<int> keypoint_indices;
  detector.compute(keypoint_indices);
  std::vector<int> indices(keypoint_indices.begin(), keypoint_indices.end());
  pcl::NarfDescriptor narf(&range_image, &indices);
  narf.getParameters().support_size = static_cast<float>(config.narf_support_m);
  // The robot stays upright (roll, pitch of a few degrees), so the image's up is the same in both
  // scans: the descriptor keeps its orientation (matched correctly 15 % vs 8 % rotation-invariant).
  narf.getParameters().rotation_invariant = false;
  pcl::PointCloud<pcl::Narf36> narfs;
  narf.compute(narfs);
  keypoints.reset(new CloudXyz);
  descriptors.reset(new pcl::PointCloud<pcl::Narf36>);
  for (const pcl::Narf36& d : narfs) {
    keypoints->push_back(pcl::PointXYZ(d.x, d.y, d.z));
    descriptors->push_back(d);
  }
}

}  // namespace

PclAlignment PclInitialAlignment(const PointCloud& target, const PointCloud& source,
                                 const PointCloud& target_dense, const PointCloud& source_dense,
                                 const RegistrationConfig& config) {
  PclAlignment out;
  auto t = std::chrono::steady_clock::now();
  const CloudXyz::Ptr tc = ToPcl(target), sc = ToPcl(source);
  if (config.features == FeatureKind::kNarf) {
    const CloudXyz::Ptr td_cloud = ToPcl(target_dense), sd_cloud = ToPcl(source_dense);
    CloudXyz::Ptr tk, sk;
    pcl::PointCloud<pcl::Narf36>::Ptr td, sd;
    Narf(td_cloud, config, tk, td);
    Narf(sd_cloud, config, sk, sd);
    out.features_s = Since(t);
    out.keypoints = static_cast<int>(std::min(tk->size(), sk->size()));
    if (tk->size() < 3 || sk->size() < 3) return out;
    out = RunSacIa<pcl::Narf36>(tk, sk, td, sd, config, out);
    out.correspondences = static_cast<int>(sk->size());
    out.sac_s = Since(t);
    return out;
  }
  const auto tn = Normals(tc, config.normal_radius_m), sn = Normals(sc, config.normal_radius_m);
  out.normals_s = Since(t);
  pcl::PointCloud<pcl::FPFHSignature33>::Ptr tf(new pcl::PointCloud<pcl::FPFHSignature33>);
  pcl::PointCloud<pcl::FPFHSignature33>::Ptr sf(new pcl::PointCloud<pcl::FPFHSignature33>);
  for (auto [cloud, normals, features] : {std::tuple{tc, tn, tf}, {sc, sn, sf}}) {
    pcl::FPFHEstimation<pcl::PointXYZ, pcl::Normal, pcl::FPFHSignature33> fpfh;
    fpfh.setInputCloud(cloud);
    fpfh.setInputNormals(normals);
    fpfh.setSearchMethod(
        pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
    fpfh.setRadiusSearch(config.feature_radius_m);
    fpfh.compute(*features);
  }
  out.features_s = Since(t);
  out = RunSacIa<pcl::FPFHSignature33>(tc, sc, tf, sf, config, out);
  out.sac_s = Since(t);
  return out;
}

PclIcp PclIcpNonLinear(const PointCloud& target, const PointCloud& source,
                       const Eigen::Isometry3d& init, const RegistrationConfig& config) {
  pcl::IterativeClosestPointNonLinear<pcl::PointXYZ, pcl::PointXYZ> icp;
  icp.setInputSource(ToPcl(source));
  icp.setInputTarget(ToPcl(target));
  icp.setMaxCorrespondenceDistance(config.icp_max_distance_m);
  icp.setMaximumIterations(config.icp_max_iterations);
  icp.setEuclideanFitnessEpsilon(config.icp_epsilon);
  icp.setTransformationEpsilon(1e-10);
  CloudXyz aligned;
  icp.align(aligned, init.matrix().cast<float>());
  PclIcp out;
  out.T_target_source.matrix() = icp.getFinalTransformation().cast<double>();
  out.converged = icp.hasConverged();
  out.iterations = config.icp_max_iterations;  // PCL does not expose the count it ran
  return out;
}

NarfFeatures ComputeNarf(const PointCloud& dense, const RegistrationConfig& config) {
  CloudXyz::Ptr keypoints;
  pcl::PointCloud<pcl::Narf36>::Ptr descriptors;
  Narf(ToPcl(dense), config, keypoints, descriptors);
  NarfFeatures out;
  out.descriptors.resize(static_cast<int>(descriptors->size()), 36);
  for (std::size_t i = 0; i < descriptors->size(); ++i) {
    const pcl::Narf36& d = (*descriptors)[i];
    out.keypoints.emplace_back(d.x, d.y, d.z);
    for (int k = 0; k < 36; ++k) out.descriptors(static_cast<int>(i), k) = d.descriptor[k];
  }
  return out;
}

PointCloud PclVoxelGrid(const PointCloud& cloud, double leaf_m) {
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setInputCloud(ToPcl(cloud));
  const float leaf = static_cast<float>(leaf_m);
  grid.setLeafSize(leaf, leaf, leaf);
  CloudXyz out;
  grid.filter(out);
  PointCloud result;
  result.reserve(out.size());
  for (const pcl::PointXYZ& p : out) result.emplace_back(p.x, p.y, p.z);
  return result;
}

}  // namespace pitchlab::mapping
