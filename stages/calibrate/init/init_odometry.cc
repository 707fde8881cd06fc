#include "stages/calibrate/init/init_odometry.h"

#include <algorithm>
#include <future>
#include <memory>
#include <optional>
#include <string>

#include "common/spline/so3_spline.h"
#include "stages/calibrate/init/coarse_time_offset.h"
#include "stages/calibrate/problem/problem_builder.h"

namespace tiltcal::calibrate {
namespace {

// Deskews scan k with the state's rotation spline and the rig's C_bl,
// T_{lk a} T_{a l(t_j)} p, into *deskewed. False when the sweep is outside
// the spline.
bool DeskewScan(const CalibrationState& state, const LidarScan& scan, double node_spacing_s,
                ScanPoseTable* table, std::vector<Eigen::Vector3f>* deskewed) {
  if (!table->Build(state, scan, node_spacing_s)) return false;
  Eigen::Quaterniond q_k;
  Eigen::Vector3d t_k;
  table->Interpolate(0.0, &q_k, &t_k);
  const Eigen::Quaterniond q_k_inv = q_k.conjugate();
  deskewed->resize(scan.points.size());
  for (size_t j = 0; j < scan.points.size(); ++j) {
    Eigen::Quaterniond q;
    Eigen::Vector3d t;
    table->Interpolate(scan.point_time_s[j], &q, &t);
    (*deskewed)[j] = (q_k_inv * (q * scan.points[j].cast<double>() + t - t_k)).cast<float>();
  }
  return true;
}

// Registers every odometry.scan_step-th scan (deskewed with the state's
// rotation spline and its prediction from the gyro when gyro_aided) into
// run.poses, with the scan index and C_ab of each pose.
OdometryRun RegisterScans(const std::vector<LidarScan>& scans, const CalibrationState& state,
                          const proto::CalibrateParams& params, bool gyro_aided) {
  const double tau = state.time_offset_s[0];
  const int num_threads = std::max(static_cast<int>(params.num_threads()), 1);
  LidarOdometry odometry(params.odometry(), params.scans(), num_threads);
  const spline::SplineTrajectory& traj = state.trajectory;
  const Eigen::Quaterniond c_bl = state.ImuFromLidarRotation();
  OdometryRun run;
  bool have_first = false;
  Eigen::Quaterniond c_ab_first = Eigen::Quaterniond::Identity();
  const size_t scan_step = std::max<size_t>(params.odometry().scan_step(), 1);
  // Scan k deskewed and prepared for registration (reads only the state).
  struct Prepared {
    bool usable = false;
    Eigen::Quaterniond c_ab = Eigen::Quaterniond::Identity();  // C_ab at the scan time
    std::shared_ptr<LidarOdometry::PreparedScan> scan;
  };
  auto prepare = [&](size_t k, int threads) {
    Prepared out;
    const LidarScan& scan = scans[k];
    if (scan.points.empty()) return out;
    spline::So3SplineSample rot;
    if (!traj.Evaluate(scan.stamp_s + tau, spline::kSo3Rotation, &rot, nullptr)) return out;
    std::vector<Eigen::Vector3f> deskewed;
    ScanPoseTable table;
    if (!gyro_aided) {
      deskewed = scan.points;
    } else if (!DeskewScan(state, scan, params.init().deskew_node_spacing_s(), &table,
                           &deskewed)) {
      return out;
    }
    out.usable = true;
    out.c_ab = Eigen::Quaterniond(rot.rotation);
    out.scan = odometry.Prepare(deskewed, threads);
    return out;
  };
  // With two threads or more, scan k + scan_step is prepared (on one thread)
  // while scan k is registered.
  const bool ahead = num_threads > 1;
  std::future<Prepared> next;
  if (!scans.empty()) next = std::async(std::launch::deferred, prepare, size_t{0}, num_threads);
  for (size_t k = 0; k < scans.size(); k += scan_step) {
    const Prepared current = next.get();
    if (k + scan_step < scans.size()) {
      next = std::async(ahead ? std::launch::async : std::launch::deferred, prepare,
                        k + scan_step, ahead ? 1 : num_threads);
    }
    if (!current.usable) continue;
    if (!have_first) {
      c_ab_first = current.c_ab;
      have_first = true;
    }
    std::optional<Eigen::Quaterniond> prior;
    if (gyro_aided) prior = LidarRotationPriorFromImu(c_ab_first, current.c_ab, c_bl);
    odometry.AddPrepared(scans[k].stamp_s, *current.scan, prior);
    run.scan_of_pose.push_back(static_cast<int>(k));
    run.imu_rotations.push_back(current.c_ab);
  }
  run.poses = odometry.poses();
  return run;
}

// The poses the coarse tau and the hand-eye use (the first and the
// registered ones) into run->used, run->imu_used and run->lidar_used, and
// the odometry's counts and mean registration quality into *report.
void SelectRegisteredPoses(OdometryRun* run, InitialisationReport* report) {
  report->odometry_scans = static_cast<int>(run->poses.size());
  double fitness_sum = 0.0;
  double inlier_fraction_sum = 0.0;
  int measured = 0;
  for (size_t i = 0; i < run->poses.size(); ++i) {
    const LidarOdometryPose& pose = run->poses[i];
    if (i > 0 && !pose.registered) continue;
    if (i > 0) {
      ++report->odometry_registered;
      if (pose.num_quality_points > 0) {
        fitness_sum += pose.fitness_rms_m;
        inlier_fraction_sum += pose.inlier_fraction;
        ++measured;
      }
    }
    run->used.push_back(i);
    run->imu_used.push_back(run->imu_rotations[i]);
    run->lidar_used.push_back(Eigen::Quaterniond(pose.l0_from_lidar.rotation()));
  }
  report->odometry_quality_scans = measured;
  if (measured > 0) {
    report->odometry_mean_fitness_m = fitness_sum / measured;
    report->odometry_mean_inlier_fraction = inlier_fraction_sum / measured;
  }
}

}  // namespace

OdometryRun RunOdometry(const std::vector<LidarScan>& scans, const CalibrationState& state,
                        const proto::CalibrateParams& params, bool gyro_aided,
                        InitialisationReport* report) {
  report->odometry_scans = 0;
  report->odometry_registered = 0;
  report->odometry_quality_scans = 0;
  report->odometry_mean_fitness_m = 0.0;
  report->odometry_mean_inlier_fraction = 0.0;
  OdometryRun run = RegisterScans(scans, state, params, gyro_aided);
  SelectRegisteredPoses(&run, report);
  return run;
}

Status EstimateCoarseTau(const OdometryRun& run, const std::vector<LidarScan>& scans,
                         const std::vector<imu::ImuReading>& imu_samples,
                         const proto::CalibrateParams& params, const CalibrationState& state,
                         InitialisationReport* report) {
  const proto::InitParams& init = params.init();
  report->time_offset_center_s = 0.0;
  if (init.coarse_time_offset_window_s() <= 0.0) return Status::Ok();
  std::vector<double> times;
  for (const size_t i : run.used) times.push_back(scans[run.scan_of_pose[i]].stamp_s);
  CoarseTimeOffset coarse;
  const Status status =
      EstimateCoarseTimeOffset(GyroAngularSpeeds(imu_samples, state.GyroBias()),
                               LidarAngularSpeeds(times, run.lidar_used), init, &coarse);
  report->coarse = coarse;
  if (!status.ok()) {
    report->coarse.distrust_reason = status.message();
    report->coarse.trusted = false;
    return Status::Ok();
  }
  if (!coarse.trusted) return Status::Ok();
  const double step = init.time_offset_search_step_s();
  const double tau = coarse.alignment.time_offset_s;
  report->time_offset_center_s = step > 0.0 ? std::round(tau / step) * step : tau;
  return Status::Ok();
}

}  // namespace tiltcal::calibrate
