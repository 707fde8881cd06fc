#include "stages/calibrate/odometry/lidar_odometry.h"

#include "common/geometry/angles.h"
#include "common/registration/point_to_plane_icp.h"
#include "common/registration/voxel_downsample.h"
#include "common/registration/voxel_hash_map.h"
#include "stages/calibrate/odometry/gicp_covariances.h"
#include "stages/calibrate/odometry/single_query_kd_tree.h"
#include "stages/calibrate/problem/surfel_map.h"

#include <chrono>
#include <cmath>
#include <deque>
#include <future>
#include <memory>

#include <pcl/common/transforms.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/registration/ndt.h>

namespace tiltcal::calibrate {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

// The spread across a GICP plane (m^2): PCL's fixed value, which it offers
// no setter for, so the covariances computed here are the ones it would use.
constexpr double kGicpEpsilon = 0.001;

// GICP's search structures for one cloud, built here rather than by GICP so
// that the point covariances use num_threads threads (gicp_covariances.h):
// its k-d tree and, when it has at least k points, its covariances (null
// otherwise: GICP then computes and refuses them itself).
struct GicpSearch {
  std::shared_ptr<SingleQueryKdTree> tree;
  std::shared_ptr<GicpCovariances> covariances;
};

GicpSearch MakeGicpSearch(const Cloud::ConstPtr& cloud, int k, int num_threads) {
  GicpSearch search{std::make_shared<SingleQueryKdTree>(), nullptr};
  search.tree->setInputCloud(cloud);
  auto covariances = std::make_shared<GicpCovariances>();
  if (ComputeGicpCovariances(*cloud, *search.tree, k, kGicpEpsilon, num_threads,
                             covariances.get())) {
    search.covariances = std::move(covariances);
  }
  return search;
}

Cloud::Ptr Downsample(const Cloud::ConstPtr& in, double leaf_m) {
  Cloud::Ptr out(new Cloud);
  if (in->empty() || !(leaf_m > 0.0)) {
    *out = *in;
    return out;
  }
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  const float leaf = static_cast<float>(leaf_m);
  grid.setLeafSize(leaf, leaf, leaf);
  grid.setInputCloud(in);
  grid.filter(*out);
  return out;
}

double RotationAngle(const Eigen::Matrix3d& c) {
  return Eigen::AngleAxisd(c).angle();
}

Eigen::Isometry3d Orthonormalised(const Eigen::Matrix4d& m) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(Eigen::Matrix3d(m.block<3, 3>(0, 0))).normalized().toRotationMatrix();
  t.translation() = m.block<3, 1>(0, 3);
  return t;
}

registration::VoxelHashMapOptions VoxelMapOptions(const proto::VoxelIcpParams& p) {
  registration::VoxelHashMapOptions options;
  options.voxel_m = p.cell_m();
  options.max_points_per_voxel = static_cast<int>(p.max_points_per_cell());
  options.min_plane_points = static_cast<int>(p.min_plane_points());
  options.max_plane_thickness_m = p.max_plane_thickness_m();
  options.min_plane_spread_ratio = p.min_plane_spread_ratio();
  return options;
}

registration::PointToPlaneIcpOptions IcpOptions(const proto::LidarOdometryParams& p) {
  registration::PointToPlaneIcpOptions options;
  options.max_iterations = static_cast<int>(p.max_iterations());
  options.max_correspondence_m = p.voxel_icp().max_correspondence_m();
  options.kernel_scale_m = p.voxel_icp().kernel_scale_m();
  options.convergence_rotation_rad = p.voxel_icp().convergence_rotation_rad();
  options.convergence_translation_m = p.voxel_icp().convergence_translation_m();
  options.min_correspondences = static_cast<int>(p.voxel_icp().min_correspondences());
  options.num_threads = static_cast<int>(p.voxel_icp().num_threads());
  return options;
}

std::vector<Eigen::Vector3d> Transformed(const Eigen::Isometry3d& t,
                                         const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(points.size());
  for (const Eigen::Vector3d& p : points) out.push_back(t * p);
  return out;
}

// VOXEL_ICP: every scan is registered against the voxel hash map, then its
// points (at map_voxel_m) enter the map; a scan counts as a keyframe when it
// is the first one.
class VoxelIcpOdometry {
 public:
  VoxelIcpOdometry(const proto::LidarOdometryParams& params, const proto::LidarScanParams& scans)
      : params_(params), scans_(scans), map_(VoxelMapOptions(params.voxel_icp())),
        icp_options_(IcpOptions(params)) {}

  // Registers the cropped scan from `guess` (unless it is the first scan or
  // the map is empty), fills pose's registration fields and adds the scan.
  void Register(const std::vector<Eigen::Vector3f>& points_lidar, const Eigen::Isometry3d& guess,
                LidarOdometryPose* pose) {
    std::vector<Eigen::Vector3d> cropped;
    cropped.reserve(points_lidar.size());
    const float min_sq = static_cast<float>(scans_.min_range_m() * scans_.min_range_m());
    const float max_sq = static_cast<float>(scans_.max_range_m() * scans_.max_range_m());
    for (const Eigen::Vector3f& p : points_lidar) {
      const float r_sq = p.squaredNorm();
      if (!p.allFinite() || r_sq < min_sq || r_sq > max_sq) continue;
      cropped.push_back(p.cast<double>());
    }
    const std::vector<Eigen::Vector3d> for_map = registration::VoxelDownsample(cropped, params_.map_voxel_m());
    const std::vector<Eigen::Vector3d> source = registration::VoxelDownsample(for_map, params_.scan_voxel_m());
    pose->num_source_points = static_cast<int>(source.size());
    pose->l0_from_lidar = guess;
    if (map_.empty()) {
      pose->keyframe = !for_map.empty();
    } else if (source.size() >= 10) {
      const registration::PointToPlaneIcpResult result =
          registration::AlignPointToPlane(source, map_, guess, icp_options_);
      pose->converged = result.converged;
      pose->num_quality_points = result.num_correspondences;
      pose->inlier_fraction = result.num_correspondences > 0
                                  ? static_cast<double>(result.num_inliers) / result.num_correspondences
                                  : 0.0;
      pose->fitness_rms_m = result.inlier_rms_m;
      if (result.registered && result.map_from_source.matrix().allFinite()) {
        pose->l0_from_lidar = result.map_from_source;
        pose->registered = true;
      }
    }
    if (map_.empty() || pose->registered) {
      map_.AddPoints(Transformed(pose->l0_from_lidar, for_map));
      map_.RemoveFarFrom(pose->l0_from_lidar.translation(), params_.voxel_icp().map_radius_m());
    }
  }

 private:
  proto::LidarOdometryParams params_;
  proto::LidarScanParams scans_;
  registration::VoxelHashMap map_;
  registration::PointToPlaneIcpOptions icp_options_;
};

}  // namespace

struct LidarOdometry::PreparedScan {
  std::vector<Eigen::Vector3f> points_lidar;  // VOXEL_ICP: the scan as given
  // GICP / NDT with registration_quality: cropped, full resolution (shared
  // with a keyframe made of it); null otherwise.
  std::shared_ptr<const std::vector<Eigen::Vector3f>> cropped;
  Cloud::Ptr source;        // GICP / NDT: downsampled at scan_voxel_m
  GicpSearch source_search;  // GICP: of `source`
};

struct LidarOdometry::Impl {
  struct Keyframe {
    Cloud::Ptr map_cloud;  // in l0, downsampled at map_voxel_m
    // Cropped, full resolution, LiDAR frame; shared with the quality map's
    // builder (null without registration_quality).
    std::shared_ptr<const std::vector<Eigen::Vector3f>> points;
    Eigen::Isometry3d pose;  // T_{l0 l}
  };

  proto::LidarOdometryParams params;
  proto::LidarScanParams scans;
  std::vector<LidarOdometryPose> poses;
  std::vector<std::optional<Eigen::Quaterniond>> priors;
  std::deque<Keyframe> keyframes;
  Eigen::Isometry3d last_keyframe_pose = Eigen::Isometry3d::Identity();
  Cloud::Ptr target;
  std::unique_ptr<SurfelMap> quality_map;  // surfels of the local map, frame l0
  // The quality map of the latest keyframe, built while the next scan is
  // registered (on the calling thread at its first use when num_threads is 1).
  std::future<std::unique_ptr<SurfelMap>> next_quality_map;
  pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
  pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> ndt;
  std::unique_ptr<VoxelIcpOdometry> voxel_icp;  // set for method VOXEL_ICP
  int num_threads = 1;  // of GICP's point covariances

  Impl(const proto::LidarOdometryParams& p, const proto::LidarScanParams& s, int threads)
      : params(p), scans(s), num_threads(std::max(threads, 1)) {
    if (p.method() == proto::LidarOdometryParams::VOXEL_ICP) {
      voxel_icp = std::make_unique<VoxelIcpOdometry>(p, s);
    }
    const int max_iterations = static_cast<int>(p.max_iterations());
    gicp.setMaximumIterations(max_iterations);
    gicp.setTransformationEpsilon(p.transformation_epsilon());
    gicp.setMaxCorrespondenceDistance(p.max_correspondence_m());
    gicp.setCorrespondenceRandomness(static_cast<int>(p.gicp_neighbours()));
    gicp.setMaximumOptimizerIterations(static_cast<int>(p.gicp_optimizer_iterations()));
    ndt.setResolution(static_cast<float>(p.ndt_resolution_m()));
    ndt.setStepSize(p.ndt_step_size_m());
    ndt.setTransformationEpsilon(p.transformation_epsilon());
    ndt.setMaximumIterations(max_iterations);
  }

  bool UsesGicp() const { return params.method() == proto::LidarOdometryParams::GICP; }

  // GICP's input clouds with their search structures (MakeGicpSearch): the
  // same neighbours as PCL's own trees, without an OpenMP region per query,
  // and trees GICP is told not to rebuild.
  void SetGicpTarget(const Cloud::ConstPtr& cloud) {
    const GicpSearch search =
        MakeGicpSearch(cloud, static_cast<int>(params.gicp_neighbours()), num_threads);
    gicp.setSearchMethodTarget(search.tree, /*force_no_recompute=*/true);
    gicp.setInputTarget(cloud);
    if (search.covariances) gicp.setTargetCovariances(search.covariances);
  }
  void SetGicpSource(const PreparedScan& scan) {
    gicp.setSearchMethodSource(scan.source_search.tree, /*force_no_recompute=*/true);
    gicp.setInputSource(scan.source);
    if (scan.source_search.covariances) gicp.setSourceCovariances(scan.source_search.covariances);
  }

  // Range crop (also into *cropped, unless null) and voxel downsampling
  // (returned).
  Cloud::Ptr Preprocess(const std::vector<Eigen::Vector3f>& points, std::vector<Eigen::Vector3f>* cropped) const {
    Cloud::Ptr cloud(new Cloud);
    cloud->reserve(points.size());
    if (cropped != nullptr) {
      cropped->clear();
      cropped->reserve(points.size());
    }
    const float min_sq = static_cast<float>(scans.min_range_m() * scans.min_range_m());
    const float max_sq = static_cast<float>(scans.max_range_m() * scans.max_range_m());
    for (const Eigen::Vector3f& p : points) {
      const float r_sq = p.squaredNorm();
      if (!p.allFinite() || r_sq < min_sq || r_sq > max_sq) continue;
      cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
      if (cropped != nullptr) cropped->push_back(p);
    }
    return Downsample(cloud, params.scan_voxel_m());
  }

  void AddKeyframe(const Cloud::ConstPtr& scan_lidar,
                   std::shared_ptr<const std::vector<Eigen::Vector3f>> points,
                   const Eigen::Isometry3d& pose) {
    Cloud::Ptr in_l0(new Cloud);
    pcl::transformPointCloud(*scan_lidar, *in_l0, pose.matrix().cast<float>());
    keyframes.push_back(Keyframe{Downsample(in_l0, params.map_voxel_m()), std::move(points), pose});
    while (static_cast<int>(keyframes.size()) > std::max(static_cast<int>(params.local_map_keyframes()), 1)) {
      keyframes.pop_front();
    }
    Cloud::Ptr merged(new Cloud);
    for (const Keyframe& k : keyframes) *merged += *k.map_cloud;
    target = Downsample(merged, params.map_voxel_m());
    if (UsesGicp()) {
      SetGicpTarget(target);
    } else {
      ndt.setInputTarget(target);
    }
    last_keyframe_pose = pose;
    if (!params.registration_quality()) return;
    // Quality reference: surfels of the full-resolution local map.
    std::vector<std::pair<Eigen::Isometry3d, std::shared_ptr<const std::vector<Eigen::Vector3f>>>>
        map_scans;
    for (const Keyframe& k : keyframes) map_scans.emplace_back(k.pose, k.points);
    next_quality_map = std::async(
        num_threads > 1 ? std::launch::async : std::launch::deferred,
        [map_params = params.quality_map(), map_scans = std::move(map_scans)] {
          auto map = std::make_unique<SurfelMap>(map_params);
          for (const auto& [scan_pose, points] : map_scans) map->AddPoints(scan_pose, *points);
          map->ExtractSurfels();
          return map;
        });
  }

  Eigen::Isometry3d Predict(double time_s, const std::optional<Eigen::Quaterniond>& prior) const {
    const std::size_t n = poses.size();
    const Eigen::Isometry3d& p1 = poses[n - 1].l0_from_lidar;
    Eigen::Isometry3d pred = Eigen::Isometry3d::Identity();
    // Rotation.
    if (prior && priors[n - 1]) {
      const Eigen::Quaterniond delta = priors[n - 1]->conjugate() * (*prior);
      pred.linear() = p1.linear() * delta.normalized().toRotationMatrix();
    } else if (n >= 2) {
      const Eigen::Matrix3d& c2 = poses[n - 2].l0_from_lidar.linear();
      pred.linear() = p1.linear() * (c2.transpose() * p1.linear());
    } else {
      pred.linear() = p1.linear();
    }
    // Translation: constant body-frame velocity.
    pred.translation() = p1.translation();
    if (n >= 2) {
      const Eigen::Isometry3d& p2 = poses[n - 2].l0_from_lidar;
      const double dt_prev = poses[n - 1].time_s - poses[n - 2].time_s;
      const double dt = time_s - poses[n - 1].time_s;
      const double scale = dt_prev > 0.0 ? dt / dt_prev : 1.0;
      const Eigen::Matrix3d turn = p1.linear() * p2.linear().transpose();
      pred.translation() += scale * (turn * (p1.translation() - p2.translation()));
    }
    return pred;
  }

  // Point-to-plane agreement of the aligned (downsampled) scan with the
  // local map's surfels.
  void Quality(const Cloud& aligned, LidarOdometryPose* pose) {
    if (next_quality_map.valid()) quality_map = next_quality_map.get();
    if (aligned.empty() || !quality_map) return;
    const double gate = params.quality_inlier_distance_m();
    double sum_sq = 0.0;
    int covered = 0, inliers = 0;
    for (const pcl::PointXYZ& p : aligned.points) {
      const Eigen::Vector3d q(p.x, p.y, p.z);
      const int index = quality_map->SurfelIndexAt(q);
      if (index < 0) continue;
      ++covered;
      const Surfel& s = quality_map->surfels()[static_cast<std::size_t>(index)];
      const double d = s.normal.dot(q) + s.offset_m;
      if (std::abs(d) <= gate) {
        sum_sq += d * d;
        ++inliers;
      }
    }
    pose->num_quality_points = covered;
    pose->inlier_fraction = covered > 0 ? static_cast<double>(inliers) / covered : 0.0;
    pose->fitness_rms_m = inliers > 0 ? std::sqrt(sum_sq / inliers) : 0.0;
  }
};

LidarOdometry::LidarOdometry(const proto::LidarOdometryParams& params,
                             const proto::LidarScanParams& scans, int num_threads)
    : impl_(std::make_unique<Impl>(params, scans, num_threads)) {}

LidarOdometry::~LidarOdometry() = default;

const std::vector<LidarOdometryPose>& LidarOdometry::poses() const { return impl_->poses; }

const LidarOdometryPose& LidarOdometry::AddScan(double time_s,
                                                const std::vector<Eigen::Vector3f>& points_lidar,
                                                const std::optional<Eigen::Quaterniond>& rotation_prior) {
  return AddPrepared(time_s, *Prepare(points_lidar, impl_->num_threads), rotation_prior);
}

std::shared_ptr<LidarOdometry::PreparedScan> LidarOdometry::Prepare(
    const std::vector<Eigen::Vector3f>& points_lidar, int num_threads) const {
  const Impl& m = *impl_;
  auto scan = std::make_shared<PreparedScan>();
  if (m.voxel_icp) {
    scan->points_lidar = points_lidar;
    return scan;
  }
  if (m.params.registration_quality()) {
    std::vector<Eigen::Vector3f> cropped;
    scan->source = m.Preprocess(points_lidar, &cropped);
    scan->cropped = std::make_shared<const std::vector<Eigen::Vector3f>>(std::move(cropped));
  } else {
    scan->source = m.Preprocess(points_lidar, nullptr);
  }
  if (m.UsesGicp() && !scan->source->empty()) {
    scan->source_search =
        MakeGicpSearch(scan->source, static_cast<int>(m.params.gicp_neighbours()), num_threads);
  }
  return scan;
}

const LidarOdometryPose& LidarOdometry::AddPrepared(
    double time_s, const PreparedScan& scan, const std::optional<Eigen::Quaterniond>& rotation_prior) {
  Impl& m = *impl_;
  const auto start = std::chrono::steady_clock::now();
  LidarOdometryPose pose;
  pose.time_s = time_s;
  if (m.voxel_icp) {
    const Eigen::Isometry3d guess =
        m.poses.empty() ? Eigen::Isometry3d::Identity() : m.Predict(time_s, rotation_prior);
    m.voxel_icp->Register(scan.points_lidar, guess, &pose);
    pose.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    m.poses.push_back(pose);
    m.priors.push_back(rotation_prior);
    return m.poses.back();
  }
  const Cloud::Ptr& source = scan.source;
  pose.num_source_points = static_cast<int>(source->size());

  if (m.poses.empty() || !m.target || m.target->empty()) {
    // First scan (or no map yet): it defines l0 / starts the map.
    pose.l0_from_lidar = m.poses.empty() ? Eigen::Isometry3d::Identity() : m.Predict(time_s, rotation_prior);
    if (!source->empty()) {
      m.AddKeyframe(source, scan.cropped, pose.l0_from_lidar);
      pose.keyframe = true;
    }
  } else {
    const Eigen::Isometry3d guess = m.Predict(time_s, rotation_prior);
    pose.l0_from_lidar = guess;
    if (source->size() >= 10) {
      Cloud aligned;
      const Eigen::Matrix4f guess_f = guess.matrix().cast<float>();
      Eigen::Matrix4f result;
      if (m.UsesGicp()) {
        m.SetGicpSource(scan);
        m.gicp.align(aligned, guess_f);
        pose.converged = m.gicp.hasConverged();
        result = m.gicp.getFinalTransformation();
      } else {
        m.ndt.setInputSource(source);
        m.ndt.align(aligned, guess_f);
        pose.converged = m.ndt.hasConverged();
        result = m.ndt.getFinalTransformation();
      }
      if (result.allFinite()) {
        pose.l0_from_lidar = Orthonormalised(result.cast<double>());
        pose.registered = true;
        m.Quality(aligned, &pose);
      }
    }
    const Eigen::Isometry3d since_keyframe = m.last_keyframe_pose.inverse() * pose.l0_from_lidar;
    if (pose.registered &&
        (since_keyframe.translation().norm() > m.params.keyframe_distance_m() ||
         geometry::RadToDeg(RotationAngle(since_keyframe.linear())) >
             m.params.keyframe_angle_deg())) {
      m.AddKeyframe(source, scan.cropped, pose.l0_from_lidar);
      pose.keyframe = true;
    }
  }
  pose.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  m.poses.push_back(pose);
  m.priors.push_back(rotation_prior);
  return m.poses.back();
}

Eigen::Quaterniond LidarRotationPriorFromImu(const Eigen::Quaterniond& world_from_imu_at_first_scan,
                                             const Eigen::Quaterniond& world_from_imu_at_scan,
                                             const Eigen::Quaterniond& imu_from_lidar) {
  return (imu_from_lidar.conjugate() * world_from_imu_at_first_scan.conjugate() *
          world_from_imu_at_scan * imu_from_lidar)
      .normalized();
}

}  // namespace tiltcal::calibrate
