#pragma once
// Private: what registration derives from its target cloud alone, each part made on first demand
// and kept with the settings it was made with (RegistrationTarget's inside). A call asking with
// other settings gets the part made afresh, so a kept part never changes a result.

#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "fast_pipeline.hpp"
#include "pitchlab/mapping/cloud_statistics.hpp"
#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/mapping/registration_config.hpp"
#include "voxel_hash.hpp"

namespace pitchlab::mapping::internal {

/// The cells of ICP's target hashes: the fine one for the gates up to the normals' radius and the
/// inlier band, the coarse one for the widest gate [m].
struct IcpCells {
  float fine;
  double coarse;
};
IcpCells IcpCellsOf(const RegistrationConfig& config);

/// One cloud's side of the feature matching (FastFeatureAlignment): the hash, the normals facing
/// its sensor, then the keypoints (indices and points) and their FPFH rows.
struct FeatureSide {
  std::unique_ptr<VoxelHashIndex> index;
  Normals normals;
  std::vector<int> keys;
  PointCloud key_points;
  FeatureMatrix fpfh;
};
/// The hash and the normals of `cloud` at `config`'s feature radii.
FeatureSide FeatureGeometry(const PointCloud& cloud, const RegistrationConfig& config,
                            const Eigen::Vector3f& sensor);
/// The keypoints and their features, on what FeatureGeometry made of `cloud`.
void AddFeatures(FeatureSide& side, const PointCloud& cloud, const RegistrationConfig& config);

// A part's reference stays valid until a call asks for that part with other settings (for the
// voxel grids: other voxel sizes, which drop every part made from them): one registration asks
// with one resolved config throughout.
class TargetMemo {
 public:
  /// `cloud` must outlive the memo.
  explicit TargetMemo(const PointCloud& cloud) : cloud_(cloud) {}

  const PointCloud& cloud() const { return cloud_; }

  /// MeasureCloud of the target from `sensor`.
  const CloudStatistics& Statistics(const Eigen::Vector3f& sensor);

  /// The target after the voxel grid: at icp_voxel_m (ICP's), and that at feature_voxel_m.
  struct Voxels {
    double icp_voxel_m = 0, feature_voxel_m = 0;
    PointCloud icp, features;
  };
  const Voxels& VoxelGrids(const RegistrationConfig& config);

  /// ICP's target (IcpScene): hashes of the ICP cloud with IcpCellsOf's edges, and its normals
  /// within `normal_radius` facing `sensor`, searched on the fine hash as ICP first reads them.
  struct Icp {
    double icp_voxel_m = 0;
    IcpCells cells{0, 0};
    float normal_radius = 0;
    Eigen::Vector3f sensor = Eigen::Vector3f::Zero();
    std::unique_ptr<VoxelHashIndex> fine, coarse;
    std::unique_ptr<LazyNormals> normals;  // made as ICP reads them
  };
  const Icp& IcpParts(const RegistrationConfig& config, const Eigen::Vector3f& sensor);

  /// The feature cloud's side of the matching at the config's own scale (FastFeatureAlignment's
  /// first try), with the settings it was made with.
  struct Features {
    double icp_voxel_m = 0, feature_voxel_m = 0;
    float normal_radius = 0, feature_radius = 0;
    int max_feature_points = 0, max_neighbors = 0;
    Eigen::Vector3f sensor = Eigen::Vector3f::Zero();
    FeatureSide side;
  };
  const FeatureSide& FeatureParts(const RegistrationConfig& config, const Eigen::Vector3f& sensor);

 private:
  const PointCloud& cloud_;
  std::optional<Eigen::Vector3f> statistics_sensor_;
  CloudStatistics statistics_;
  std::optional<Voxels> voxels_;
  std::optional<Icp> icp_;
  std::optional<Features> features_;
};

}  // namespace pitchlab::mapping::internal
