#ifndef TILTCAL_STAGES_CALIBRATE_ODOMETRY_LIDAR_ODOMETRY_H_
#define TILTCAL_STAGES_CALIBRATE_ODOMETRY_LIDAR_ODOMETRY_H_

// Scan-to-local-map LiDAR odometry on deskewed scans, for the position
// initialisation of the calibrator (docs/design.md §9; OA-Calib's NDT
// odometry). Settings: proto::LidarOdometryParams.
//
// Frames: each scan's points are in its LiDAR frame l_k at the scan time
// (deskewed). Poses are T_{l0 lk} = (C_{l0 lk}, r_{l0}^{lk l0}), i.e.
// l0_from_lidar, with l0 the first scan's LiDAR frame (so pose 0 = identity).
//
// Per scan: a range crop (LidarScanParams min_range_m, max_range_m);
// prediction
//   C_pred = C_{l0 l(k-1)} C_prior(k-1)^T C_prior(k)   when a rotation prior
//            (e.g. gyro mapped through the measured extrinsic, see
//            LidarRotationPriorFromImu) is given, else constant rotation rate;
//   r_pred = r_{k-1} + (C_{k-1} C_{k-2}^T)(r_{k-1} - r_{k-2}) * dt_k / dt_{k-1}
//            (constant body-frame velocity);
// then registration by odometry.method:
// - VOXEL_ICP: the scan downsampled at scan_voxel_m is aligned by
//   point-to-plane ICP (common/registration/point_to_plane_icp.h) to a voxel
//   hash map in l0 (common/registration/voxel_hash_map.h); the scan
//   downsampled at map_voxel_m then enters the map, and cells beyond
//   voxel_icp.map_radius_m are dropped. Quality fields come from the ICP's
//   last linearisation. Cost on a VLP-16 scan (~2.3k points at 0.5 m):
//   ~6.5 iterations, ~8 ms of one core.
// - GICP (default) or NDT (PCL) against a local map made of the last
//   local_map_keyframes keyframes (a scan becomes a keyframe when it moved
//   more than keyframe_distance_m or keyframe_angle_deg from the last
//   keyframe), voxel-downsampled at map_voxel_m; quality (optional) against
//   the surfels of the full-resolution keyframes. GICP's neighbour searches use
//   single_query_kd_tree.h (PCL's tree without an OpenMP region per query);
//   ~12 ms of one core per scan with the keyframe maps on a 40 s sequence.
// PCL only appears in the .cc file.

#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::calibrate {

struct LidarOdometryPose {
  double time_s = 0.0;
  Eigen::Isometry3d l0_from_lidar = Eigen::Isometry3d::Identity();  // T_{l0 lk}
  bool registered = false;   // false for scan 0 and for scans that could not be registered
  bool converged = false;    // the registration reported convergence
  bool keyframe = false;
  int num_source_points = 0;  // after downsampling and cropping
  // Quality after alignment. GICP / NDT, when registration_quality is set
  // (zero otherwise): against planar surfels of the local map (the
  // keyframes at full resolution, surfel map quality_map): of the source
  // points that fall in a surfel voxel (num_quality_points), the fraction
  // within quality_inlier_distance_m of the plane and their RMS
  // point-to-plane distance (m). VOXEL_ICP: the point-to-plane
  // correspondences, the fraction within voxel_icp.kernel_scale_m and their
  // RMS. A good registration gives ~1 and ~the range noise.
  int num_quality_points = 0;
  double fitness_rms_m = 0.0;
  double inlier_fraction = 0.0;
  double seconds = 0.0;      // wall time spent on this scan, s
};

class LidarOdometry {
 public:
  // num_threads: threads of GICP's point covariances (gicp_covariances.h);
  // with two or more, a new keyframe's quality map (if any) is built while the next
  // scan is registered. The registration itself is sequential; the results
  // do not depend on the thread count.
  LidarOdometry(const proto::LidarOdometryParams& params, const proto::LidarScanParams& scans,
                int num_threads = 1);
  ~LidarOdometry();
  LidarOdometry(const LidarOdometry&) = delete;
  LidarOdometry& operator=(const LidarOdometry&) = delete;

  // Registers the next scan (times increasing). rotation_prior = predicted
  // C_{l0 lk} (only its change since the previous scan is used). Points must
  // be finite; an empty scan keeps the predicted pose with registered=false.
  const LidarOdometryPose& AddScan(double time_s, const std::vector<Eigen::Vector3f>& points_lidar,
                                   const std::optional<Eigen::Quaterniond>& rotation_prior);

  // AddScan in two steps. Prepare makes a scan ready for registration (range
  // crop and downsampling; for GICP also its k-d tree and point covariances,
  // on num_threads threads) and reads nothing of the odometry's state, so it
  // may run on another thread while the previous scan is registered.
  // AddPrepared registers it; its pose's `seconds` leave Prepare out.
  struct PreparedScan;
  std::shared_ptr<PreparedScan> Prepare(const std::vector<Eigen::Vector3f>& points_lidar,
                                        int num_threads) const;
  const LidarOdometryPose& AddPrepared(double time_s, const PreparedScan& scan,
                                       const std::optional<Eigen::Quaterniond>& rotation_prior);

  const std::vector<LidarOdometryPose>& poses() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The rotation prior of scan k from the gyro: with C_ab from gyro
// integration and the measured extrinsic rotation C_bl,
//   C_{l0 lk} = C_bl^T C_ab(t_0)^T C_ab(t_k) C_bl.
Eigen::Quaterniond LidarRotationPriorFromImu(const Eigen::Quaterniond& world_from_imu_at_first_scan,
                                             const Eigen::Quaterniond& world_from_imu_at_scan,
                                             const Eigen::Quaterniond& imu_from_lidar);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_ODOMETRY_LIDAR_ODOMETRY_H_
