#ifndef TILTCAL_STAGES_CALIBRATE_PROBLEM_SURFEL_MAP_H_
#define TILTCAL_STAGES_CALIBRATE_PROBLEM_SURFEL_MAP_H_

// Planar surfels of a voxelised point map in the world frame a, and
// point-to-surfel association (OA-Calib style map; docs/design.md §7).
//
// Frames: every point handed to the map or to Associate() is already resolved
// in a (the IMU frame at the first IMU sample). A surfel is the plane
//   n_pi^T p_a + d_pi = 0,   |n_pi| = 1,
// fitted by PCA (geometry::FitPlane) to the points of one voxel of a cubic
// grid of edge voxel_m whose cell (i, j, k) covers [i, i+1) * voxel_m etc.
//
// The map keeps per-voxel moments (geometry::PlaneMoments of the points
// relative to the voxel centre, for numerical accuracy) and a bounded,
// evenly thinned sample of the points (at most sample_points), so memory
// grows with the number of occupied voxels, not with the points.
//
// Plane fit (PCA of the moments), then a robustness check on the sample in
// place of OA-Calib's per-voxel RANSAC: sample points farther from the plane
// than 3 robust sigmas (1.4826 x median absolute residual, clamped to
// [min_inlier_distance_m, inlier_distance_m]) are outliers (e.g. the foot of
// a wall in a floor voxel); with more than (1 - min_inlier_fraction) of them
// the voxel is rejected, with fewer the plane is refitted (PCA) on the inlier
// sample (two rounds).
// Planarity gate (proto::SurfelMapParams), with the covariance eigenvalues
// l1 >= l2 >= l3 (m^2):
//   count >= min_points,
//   l2 / l1 >= min_spread_ratio       (a patch, not a line: a normal exists;
//                                      FitPlane also fails below 1e-5),
//   l3 / l2 <= max_planarity          (flat: smallest spread << middle one),
//   sqrt(l3) <= max_thickness_m       (RMS distance of the points to the plane),
//   sqrt(l3 / (n l2)) <= max_normal_sigma_deg (converted to rad)
//                       (first-order standard deviation of the fitted normal
//                        of n points with in-plane spread l2: a few noisy
//                        scan lines on a far wall give a poorly known normal).
// A voxel with a corner, an edge, a curved object or a single scan line fails
// one of them.

#include <cstdint>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/geometry/plane_fit.h"
#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::calibrate {

// One planar patch of the map, frame a.
struct Surfel {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // n_pi, unit
  double offset_m = 0.0;                              // d_pi: n_pi^T p + d_pi = 0
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero(); // mean of the voxel's points, m
  // Covariance eigenvalues, descending (l1, l2, l3), m^2.
  Eigen::Vector3d eigenvalues_m2 = Eigen::Vector3d::Zero();
  double normal_sigma_rad = 0.0;  // sqrt(l3 / (n l2))
  int num_points = 0;             // points that fell in the voxel
  Eigen::Vector3i voxel = Eigen::Vector3i::Zero();    // integer cell index
};

// Why voxels were not turned into surfels (counts over the last Extract).
struct SurfelExtractionSummary {
  int num_voxels = 0;
  int num_surfels = 0;
  int rejected_too_few_points = 0;
  int rejected_line_like = 0;    // l2 / l1 < min_spread_ratio or no plane fit (checked first)
  int rejected_not_flat = 0;     // l3 / l2 > max_planarity
  int rejected_too_thick = 0;    // sqrt(l3) > max_thickness_m
  int rejected_outliers = 0;     // inlier fraction of the sample < min_inlier_fraction
  int rejected_uncertain_normal = 0;  // sqrt(l3 / (n l2)) > max_normal_sigma_deg
  int refitted = 0;              // surfels refitted on their inlier sample
};

struct SurfelAssociation {
  int point_index = 0;    // index into the query points
  int surfel_index = 0;   // index into SurfelMap::surfels()
  double distance_m = 0;  // signed point-to-plane distance n_pi^T p + d_pi, m
};

class SurfelMap {
 public:
  explicit SurfelMap(const proto::SurfelMapParams& params);

  // Adds points measured in the LiDAR frame, moved to a by a_from_lidar
  // (p_a = C_al p_l + r_a^{la}). The sensor origin a_from_lidar.translation()
  // is remembered per voxel to orient the normals towards the sensors.
  void AddPoints(const Eigen::Isometry3d& a_from_lidar,
                 const std::vector<Eigen::Vector3f>& points_lidar);
  // Adds points already in frame a (normals then oriented only if other
  // points of the voxel came with a sensor origin).
  void AddPointsInWorld(const std::vector<Eigen::Vector3d>& points_a);

  // Fits planes in all voxels and applies the planarity gate. Surfels are in
  // increasing voxel-key order (deterministic). May be called again after
  // more points were added.
  SurfelExtractionSummary ExtractSurfels();

  const std::vector<Surfel>& surfels() const { return surfels_; }
  const proto::SurfelMapParams& params() const { return params_; }

  // Index of the surfel of the voxel containing p_a, or -1.
  int SurfelIndexAt(const Eigen::Vector3d& p_a) const;

  // Point-to-surfel association for query points in frame a: each point is
  // matched to the surfel of its own voxel when |n_pi^T p + d_pi| <=
  // params.max_distance_m and |p - centroid| <=
  // params.max_centroid_distance_factor x voxel_m (a point inside the patch
  // that the surfel describes); at most params.max_points_per_surfel_per_scan
  // points per surfel: when more qualify, evenly spaced in query order, or,
  // with priorities (one per query point), those of lowest priority.
  // Output sorted by point_index.
  std::vector<SurfelAssociation> Associate(const std::vector<Eigen::Vector3d>& points_a,
                                           const proto::AssociationParams& params,
                                           const std::vector<uint64_t>& priorities = {}) const;

  // Integer voxel index of a point in frame a.
  Eigen::Vector3i VoxelOf(const Eigen::Vector3d& p_a) const;

 private:
  struct VoxelStats {
    Eigen::Vector3i voxel = Eigen::Vector3i::Zero();
    geometry::PlaneMoments moments;  // of (p - centre)
    int num_with_sensor = 0;
    Eigen::Vector3d sum_sensor = Eigen::Vector3d::Zero(); // sum of (sensor origin - centre)
    // Every sample_stride-th point (relative to the centre); when the sample
    // is full, every other one is dropped and the stride doubles.
    std::vector<Eigen::Vector3f> sample;
    int sample_stride = 1;
  };
  // The PCA plane of moments relative to a voxel centre (surfel_map.cc).
  struct PcaResult;
  static PcaResult FitPca(const geometry::PlaneMoments& moments);
  enum class SampleCheck { kAccepted, kOutliers, kDegenerate };
  // The outlier check on a voxel's sample; refits *pca (and sets *fit_count,
  // *refitted) on the inliers when some are off.
  SampleCheck CheckSampleOutliers(const std::vector<Eigen::Vector3f>& sample, PcaResult* pca,
                                  int* fit_count, bool* refitted) const;
  // The planarity gate; counts a rejection in *summary.
  bool PassesPlanarityGate(const PcaResult& pca, int fit_count, SurfelExtractionSummary* summary,
                           double* normal_sigma_rad) const;
  Surfel MakeSurfel(const VoxelStats& stats, const PcaResult& pca, double normal_sigma_rad) const;
  static std::uint64_t Key(const Eigen::Vector3i& v);
  Eigen::Vector3d Centre(const Eigen::Vector3i& v) const;
  void Accumulate(const Eigen::Vector3d& p_a, const Eigen::Vector3d* sensor_a);

  proto::SurfelMapParams params_;
  double voxel_m_;
  std::unordered_map<std::uint64_t, VoxelStats> voxels_;
  std::unordered_map<std::uint64_t, int> surfel_of_voxel_;
  std::vector<Surfel> surfels_;
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_PROBLEM_SURFEL_MAP_H_
