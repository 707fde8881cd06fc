#include "stages/calibrate/lidar_odometry.h"

#include "stages/calibrate/surfel_map.h"

#include <chrono>
#include <cmath>
#include <deque>

#include <pcl/common/transforms.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/registration/ndt.h>

namespace tiltcal::calibrate {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

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

}  // namespace

struct LidarOdometry::Impl {
  struct Keyframe {
    Cloud::Ptr map_cloud;                  // in l0, downsampled at map_voxel_m
    std::vector<Eigen::Vector3f> points;   // cropped, full resolution, LiDAR frame
    Eigen::Isometry3d pose;                // T_{l0 l}
  };

  proto::LidarOdometryParams params;
  proto::LidarScanParams scans;
  std::vector<LidarOdometryPose> poses;
  std::vector<std::optional<Eigen::Quaterniond>> priors;
  std::deque<Keyframe> keyframes;
  Eigen::Isometry3d last_keyframe_pose = Eigen::Isometry3d::Identity();
  Cloud::Ptr target;
  std::unique_ptr<SurfelMap> quality_map;  // surfels of the local map, frame l0
  pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
  pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> ndt;

  Impl(const proto::LidarOdometryParams& p, const proto::LidarScanParams& s)
      : params(p), scans(s) {
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

  // Range crop (into *cropped) and voxel downsampling (returned).
  Cloud::Ptr Preprocess(const std::vector<Eigen::Vector3f>& points, std::vector<Eigen::Vector3f>* cropped) const {
    Cloud::Ptr cloud(new Cloud);
    cloud->reserve(points.size());
    cropped->clear();
    cropped->reserve(points.size());
    const float min_sq = static_cast<float>(scans.min_range_m() * scans.min_range_m());
    const float max_sq = static_cast<float>(scans.max_range_m() * scans.max_range_m());
    for (const Eigen::Vector3f& p : points) {
      const float r_sq = p.squaredNorm();
      if (!p.allFinite() || r_sq < min_sq || r_sq > max_sq) continue;
      cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
      cropped->push_back(p);
    }
    return Downsample(cloud, params.scan_voxel_m());
  }

  void AddKeyframe(const Cloud::ConstPtr& scan_lidar, std::vector<Eigen::Vector3f> points,
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
      gicp.setInputTarget(target);
    } else {
      ndt.setInputTarget(target);
    }
    // Quality reference: surfels of the full-resolution local map.
    quality_map = std::make_unique<SurfelMap>(params.quality_map());
    for (const Keyframe& k : keyframes) quality_map->AddPoints(k.pose, k.points);
    quality_map->ExtractSurfels();
    last_keyframe_pose = pose;
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
  void Quality(const Cloud& aligned, LidarOdometryPose* pose) const {
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
                             const proto::LidarScanParams& scans)
    : impl_(std::make_unique<Impl>(params, scans)) {}

LidarOdometry::~LidarOdometry() = default;

const std::vector<LidarOdometryPose>& LidarOdometry::poses() const { return impl_->poses; }

const LidarOdometryPose& LidarOdometry::AddScan(double time_s,
                                                const std::vector<Eigen::Vector3f>& points_lidar,
                                                const std::optional<Eigen::Quaterniond>& rotation_prior) {
  Impl& m = *impl_;
  const auto start = std::chrono::steady_clock::now();
  LidarOdometryPose pose;
  pose.time_s = time_s;
  std::vector<Eigen::Vector3f> cropped;
  const Cloud::Ptr source = m.Preprocess(points_lidar, &cropped);
  pose.num_source_points = static_cast<int>(source->size());

  if (m.poses.empty() || !m.target || m.target->empty()) {
    // First scan (or no map yet): it defines l0 / starts the map.
    pose.l0_from_lidar = m.poses.empty() ? Eigen::Isometry3d::Identity() : m.Predict(time_s, rotation_prior);
    if (!source->empty()) {
      m.AddKeyframe(source, std::move(cropped), pose.l0_from_lidar);
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
        m.gicp.setInputSource(source);
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
         RotationAngle(since_keyframe.linear()) * 180.0 / M_PI > m.params.keyframe_angle_deg())) {
      m.AddKeyframe(source, std::move(cropped), pose.l0_from_lidar);
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
