#pragma once
// PCL's implementations of the registration stages (backend "pcl"), behind our cloud type so that
// PCL's headers stay in pcl_pipeline.cpp.

#include <Eigen/Geometry>

#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/mapping/registration_config.hpp"

namespace pitchlab::mapping {

struct PclAlignment {
  bool found = false;
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  int correspondences = 0;                          // feature correspondences SAC-IA worked with
  int keypoints = 0;                                // NARF keypoints of the poorer cloud
  double normals_s = 0, features_s = 0, sac_s = 0;  // stage wall times [s]
};

/// pcl::NormalEstimation + pcl::FPFHEstimation on the feature clouds (voxelized already), or NARF
/// keypoints/descriptors on range images of the dense clouds (the scans as taken), then
/// pcl::SampleConsensusInitialAlignment.
PclAlignment PclInitialAlignment(const PointCloud& target, const PointCloud& source,
                                 const PointCloud& target_dense, const PointCloud& source_dense,
                                 const RegistrationConfig& config);

struct PclIcp {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  int iterations = 0;
  bool converged = false;
};

/// pcl::IterativeClosestPointNonLinear (Levenberg-Marquardt) from `init`.
PclIcp PclIcpNonLinear(const PointCloud& target, const PointCloud& source,
                       const Eigen::Isometry3d& init, const RegistrationConfig& config);

/// NARF keypoints of a dense scan (PCL's range image, border extractor, NarfKeypoint) and their
/// rotation-invariant 36-bin descriptors, one row per keypoint: for the fast backend's sample
/// consensus, so that Table 1 can compare the descriptors under the same initial alignment.
struct NarfFeatures {
  PointCloud keypoints;
  Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> descriptors;
};
NarfFeatures ComputeNarf(const PointCloud& dense, const RegistrationConfig& config);

/// pcl::VoxelGrid (the PCL default pipeline's downsampling, for the baseline).
PointCloud PclVoxelGrid(const PointCloud& cloud, double leaf_m);

}  // namespace pitchlab::mapping
