#include "stages/simulate/simulate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <thread>
#include <vector>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "bag/ros1/bag_writer.h"
#include "bag/ros1/message_encoding.h"
#include "common/cli/command_line.h"
#include "common/geometry/angles.h"
#include "common/geometry/euler_angles.h"
#include "common/imu/imu_units.h"
#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/provenance.h"
#include "common/io/text_proto.h"
#include "stages/simulate/fault_params.h"
#include "stages/simulate/imu_intrinsics.h"
#include "stages/simulate/imu_schedule.h"
#include "stages/simulate/imu_vibration.h"
#include "stages/simulate/point_cloud_layout.h"
#include "stages/simulate/random.h"
#include "stages/simulate/tf_static_writer.h"
#include "tiltcal/proto/rig.pb.h"

namespace tiltcal::simulate {

namespace {

using geometry::kRadPerDeg;
using geometry::kDegPerRad;
// Largest stamp a ROS time can hold.
constexpr int64_t kMaxRosTimeNs = 4294967295LL * 1000000000LL;

// The unit quaternion of `rotation` with w >= 0, the form written to disk.
proto::Rigid3 RigidToProto(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation) {
  Eigen::Quaterniond q(rotation);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  return ToProto(Rigid3d{q, translation});
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kDegPerRad;
}

// Places the random boxes and pillars inside the room, outside the track's
// bounding box grown by the clearance (rejection sampling, deterministic).
void AddRandomObstacles(const proto::SimWorldParams& p, const PlanarTrajectory& trajectory,
                        uint64_t seed, World* world) {
  Rng rng(seed, kWorldStream);
  // Track bounding box in w (x, y): the path corners mapped through the plane.
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  const Eigen::Vector2d pmin = trajectory.PathMin(), pmax = trajectory.PathMax();
  for (int c = 0; c < 4; ++c) {
    const Eigen::Vector3d corner(c & 1 ? pmax.x() : pmin.x(), c & 2 ? pmax.y() : pmin.y(), 0.0);
    const Eigen::Vector3d w = trajectory.world_from_plane() * corner;
    lo = lo.cwiseMin(w.head<2>());
    hi = hi.cwiseMax(w.head<2>());
  }
  const double clearance = p.track_clearance_m();
  const double half = p.room_half_size_m();
  auto free_spot = [&](double radius, double* x, double* y) {
    for (int attempt = 0; attempt < 1000; ++attempt) {
      *x = rng.Uniform(-half + radius + 0.5, half - radius - 0.5);
      *y = rng.Uniform(-half + radius + 0.5, half - radius - 0.5);
      const bool in_track = *x > lo.x() - clearance - radius && *x < hi.x() + clearance + radius &&
                            *y > lo.y() - clearance - radius && *y < hi.y() + clearance + radius;
      if (!in_track) return true;
    }
    return false;
  };
  for (uint32_t i = 0; i < p.num_random_boxes(); ++i) {
    const double sx = rng.Uniform(0.5, 3.0), sy = rng.Uniform(0.5, 3.0);
    const double height = rng.Uniform(0.8, 4.0);
    double x, y;
    if (!free_spot(0.5 * std::hypot(sx, sy), &x, &y)) continue;
    world->AddBox({x - 0.5 * sx, x + 0.5 * sx, y - 0.5 * sy, y + 0.5 * sy,
                   world->GroundZ(x, y) + height});
  }
  for (uint32_t i = 0; i < p.num_random_pillars(); ++i) {
    const double radius = rng.Uniform(0.1, 0.5);
    const double height = rng.Uniform(2.0, 8.0);
    double x, y;
    if (!free_spot(radius, &x, &y)) continue;
    world->AddPillar({x, y, radius, world->GroundZ(x, y) + height});
  }
}

ros1::ChunkCompression ToCompression(proto::SimBagParams::Compression c) {
  switch (c) {
    case proto::SimBagParams::BZ2: return ros1::ChunkCompression::kBz2;
    case proto::SimBagParams::LZ4: return ros1::ChunkCompression::kLz4;
    default: return ros1::ChunkCompression::kNone;
  }
}

}  // namespace

namespace {

TrajectoryConfig MakeTrajectoryConfig(const proto::SimulateParams& params) {
  const auto& tp = params.trajectory();
  TrajectoryConfig tc;
  tc.shape = tp.shape() == proto::SimTrajectoryParams::CIRCLE
                 ? TrajectoryConfig::Shape::kCircle
                 : TrajectoryConfig::Shape::kFigureEight;
  tc.length_m = tp.length_m();
  tc.width_m = tp.width_m();
  tc.speed_mps = tp.speed_mps();
  tc.static_start_s = tp.static_start_s();
  tc.ramp_s = tp.ramp_s();
  tc.vibration_roll_rad = tp.vibration_roll_deg() * kRadPerDeg;
  tc.vibration_pitch_rad = tp.vibration_pitch_deg() * kRadPerDeg;
  tc.vibration_frequency_hz = tp.vibration_frequency_hz();
  tc.heading_rad = tp.heading_deg() * kRadPerDeg;
  tc.max_yaw_rate_radps = tp.max_yaw_rate_radps();
  tc.ground_roll_rad = params.ground_roll_deg() * kRadPerDeg;
  tc.ground_pitch_rad = params.ground_pitch_deg() * kRadPerDeg;
  tc.imu_height_m = params.rig().imu_height_m();
  tc.vehicle_from_imu =
      geometry::RotationFromEuler123Deg(ToEigen(params.rig().imu_rotation_in_vehicle_deg()));
  return tc;
}

// The LiDAR model, range limits, timing and mounting of the params.
Status MakeScanConfig(const proto::SimulateParams& params, ScanConfig* sc) {
  const auto& lp = params.lidar();
  switch (lp.model()) {
    case proto::SimLidarParams::VLP_16: sc->model = Vlp16Model(); break;
    case proto::SimLidarParams::VLP_32C: sc->model = Vlp32cModel(); break;
    case proto::SimLidarParams::OS1_32: {
      const uint32_t columns = lp.ouster_columns() == 0 ? 1024 : lp.ouster_columns();
      if (columns != 512 && columns != 1024 && columns != 2048) {
        return Status::Error("field lidar.ouster_columns = " + std::to_string(columns) +
                             " must be 512, 1024 or 2048");
      }
      sc->model = Os132Model(static_cast<int>(columns));
      break;
    }
    case proto::SimLidarParams::LIVOX_AVIA: sc->model = LivoxAviaModel(); break;
    case proto::SimLidarParams::LIVOX_MID360: sc->model = LivoxMid360Model(); break;
    default:
      return Status::Error(
          "field lidar.model must be VLP_16, VLP_32C, OS1_32, LIVOX_AVIA or LIVOX_MID360");
  }
  if (lp.max_range_m() <= lp.min_range_m()) {
    return Status::Error("field lidar.max_range_m must exceed lidar.min_range_m");
  }
  sc->scan_rate_hz = lp.scan_rate_hz();
  sc->min_range_m = lp.min_range_m();
  sc->max_range_m = lp.max_range_m();
  sc->range_noise_m = lp.range_noise_m();
  sc->livox_noise_fraction = lp.livox_noise_fraction();
  sc->ground_roughness_m = params.faults().ground_roughness_m();
  const bool livox = sc->model.kind == LidarModel::Kind::kLivox;
  if (livox && lp.append_surface_label()) {
    return Status::Error("field lidar.append_surface_label: a Livox CustomMsg has no label field");
  }
  if (!livox && lp.livox_noise_fraction() > 0) {
    return Status::Error("field lidar.livox_noise_fraction applies to Livox models only");
  }
  sc->velodyne_stamp_at_start = lp.velodyne_stamp_at_start();
  sc->first_scan_time_s = lp.first_scan_time_s();
  sc->imu_from_lidar_rotation =
      geometry::RotationFromEuler123Deg(ToEigen(params.rig().lidar_rotation_in_imu_deg()));
  sc->imu_from_lidar_translation = ToEigen(params.rig().lidar_translation_in_imu_m());
  return Status::Ok();
}

// The room with its walls, the boxes and pillars of the params and the
// random obstacles; the rolling ground of the faults, its phases in
// *scenario.
std::unique_ptr<World> MakeWorld(const proto::SimulateParams& params,
                                 const PlanarTrajectory& trajectory, Scenario* scenario) {
  const auto& wp = params.world();
  auto world =
      std::make_unique<World>(trajectory.NormalInWorld(), wp.room_half_size_m(), wp.wall_height_m());
  const auto& faults = params.faults();
  if (faults.rolling_ground_amplitude_m() > 0) {
    Rng rng(params.seed(), kRollingGroundStream);
    scenario->rolling_phase_u_rad = rng.Uniform(0.0, 2.0 * M_PI);
    scenario->rolling_phase_v_rad = rng.Uniform(0.0, 2.0 * M_PI);
    world->SetRollingGround(trajectory.world_from_plane(), faults.rolling_ground_amplitude_m(),
                            faults.rolling_ground_wavelength_m(), scenario->rolling_phase_u_rad,
                            scenario->rolling_phase_v_rad);
  }
  for (const auto& b : wp.boxes()) {
    const double z = world->GroundZ(b.center_x_m(), b.center_y_m());
    world->AddBox({b.center_x_m() - 0.5 * b.size_x_m(), b.center_x_m() + 0.5 * b.size_x_m(),
                   b.center_y_m() - 0.5 * b.size_y_m(), b.center_y_m() + 0.5 * b.size_y_m(),
                   z + b.height_m()});
  }
  for (const auto& p : wp.pillars()) {
    const double z = world->GroundZ(p.center_x_m(), p.center_y_m());
    world->AddPillar({p.center_x_m(), p.center_y_m(), p.radius_m(), z + p.height_m()});
  }
  AddRandomObstacles(wp, trajectory, params.seed(), world.get());
  return world;
}

Status CheckTrackFitsRoom(const proto::SimulateParams& params,
                          const PlanarTrajectory& trajectory) {
  const double half = params.world().room_half_size_m();
  const Eigen::Vector2d pmin = trajectory.PathMin(), pmax = trajectory.PathMax();
  const double extent = std::max(pmin.cwiseAbs().maxCoeff(), pmax.cwiseAbs().maxCoeff());
  if (params.world().wall_height_m() > 0 && extent + 2.0 > half) {
    return Status::Error("field world.room_half_size_m = " + std::to_string(half) +
                         " leaves no room for the track (extent " + std::to_string(extent) +
                         " m + 2 m)");
  }
  return Status::Ok();
}

// The LiDAR must be above the ground (checked at the start pose).
Status CheckLidarAboveGround(const PlanarTrajectory& trajectory, const ScanConfig& sc) {
  Eigen::Matrix3d c_wb;
  Eigen::Vector3d r_wb;
  trajectory.Pose(0.0, &c_wb, &r_wb);
  const double lidar_height =
      trajectory.NormalInWorld().dot(r_wb + c_wb * sc.imu_from_lidar_translation);
  if (lidar_height < 0.05) {
    return Status::Error("the LiDAR is " + std::to_string(lidar_height) +
                         " m above the ground: check rig.imu_height_m, "
                         "rig.lidar_translation_in_imu_m and rig.imu_rotation_in_vehicle_deg");
  }
  return Status::Ok();
}

// Sample and sweep counts of the duration and the two clocks; every stamp
// must be a valid ROS time. LiDAR stamps are IMU clock − τ: when the first
// would be negative, the IMU clock starts at start_stamp_ns + τ instead.
Status SetTiming(const proto::SimulateParams& params, Scenario* scenario) {
  const ScanConfig& sc = scenario->scan;
  const int64_t duration_ns = std::llround(params.duration_s() * 1e9);
  scenario->num_imu_samples =
      static_cast<int>(std::floor(params.duration_s() * params.imu().rate_hz() + 1e-9)) + 1;
  const int64_t span_ns = std::llround(SweepSpanS(sc) * 1e9);
  int scans = 0;
  while (SweepStartNs(sc, scans) + span_ns <= duration_ns) ++scans;
  if (scans == 0) {
    return Status::Error("field duration_s = " + std::to_string(params.duration_s()) +
                         " is too short for one LiDAR sweep after lidar.first_scan_time_s");
  }
  scenario->num_scans = scans;
  const int64_t tau_ns = std::llround(params.rig().time_offset_s() * 1e9);
  const int64_t start = params.start_stamp_ns();
  scenario->time_offset_ns = tau_ns;
  scenario->lidar_clock_drift_ppm = params.faults().lidar_clock_drift_ppm();
  // The LiDAR clock with the IMU clock starting at `start`.
  scenario->imu_start_stamp_ns = start;
  scenario->imu_clock_shift_ns =
      scenario->LidarStampNs(SweepStartNs(sc, 0)) < 0 ? tau_ns : 0;
  scenario->imu_start_stamp_ns = start + scenario->imu_clock_shift_ns;
  // The latest stamp: the last IMU sample, or the LiDAR clock then (later
  // for τ < 0 or a fast LiDAR clock).
  if (std::max(scenario->imu_start_stamp_ns + duration_ns, scenario->LidarStampNs(duration_ns)) >
      kMaxRosTimeNs) {
    return Status::Error("field start_stamp_ns = " + std::to_string(start) +
                         " gives stamps beyond the ROS time range with this duration and "
                         "rig.time_offset_s");
  }
  return Status::Ok();
}

// Which sweeps SimFaultParams.lidar_drop_fraction leaves out (one draw per
// sweep from its own stream; the first and the last always stay).
void DropScans(const proto::SimulateParams& params, Scenario* scenario) {
  const double fraction = params.faults().lidar_drop_fraction();
  const int n = scenario->num_scans;
  scenario->scan_kept.assign(static_cast<size_t>(n), true);
  scenario->num_scans_dropped = 0;
  if (fraction <= 0) return;
  Rng rng(params.seed(), kLidarDropStream);
  for (int k = 0; k < n; ++k) {
    const bool dropped = rng.Uniform() < fraction;
    if (dropped && k > 0 && k < n - 1) {
      scenario->scan_kept[static_cast<size_t>(k)] = false;
      ++scenario->num_scans_dropped;
    }
  }
}

}  // namespace

int64_t Scenario::LidarStampNs(int64_t true_rel_ns) const {
  const int64_t drift_ns =
      lidar_clock_drift_ppm == 0.0
          ? 0
          : std::llround(static_cast<double>(true_rel_ns) * lidar_clock_drift_ppm * 1e-6);
  return imu_start_stamp_ns + true_rel_ns + drift_ns - time_offset_ns;
}

int64_t Scenario::LidarRecordNs(int64_t true_rel_ns) const {
  return imu_start_stamp_ns + true_rel_ns - time_offset_ns;
}

Status BuildScenario(const proto::SimulateParams& params, Scenario* scenario) {
  TILTCAL_RETURN_IF_ERROR(SimFaultParamsAreValid(params.faults(), params.duration_s()));
  const TrajectoryConfig tc = MakeTrajectoryConfig(params);
  if ((tc.vibration_roll_rad > 0 || tc.vibration_pitch_rad > 0) &&
      tc.vibration_frequency_hz <= 0) {
    return Status::Error("field trajectory.vibration_frequency_hz must be > 0 with a vibration");
  }
  scenario->trajectory = std::make_unique<PlanarTrajectory>(tc);
  const PlanarTrajectory& trajectory = *scenario->trajectory;
  TILTCAL_RETURN_IF_ERROR(CheckTrackFitsRoom(params, trajectory));
  TILTCAL_RETURN_IF_ERROR(MakeScanConfig(params, &scenario->scan));
  TILTCAL_RETURN_IF_ERROR(CheckLidarAboveGround(trajectory, scenario->scan));
  scenario->world = MakeWorld(params, trajectory, scenario);
  scenario->gravity_w = Eigen::Vector3d(0.0, 0.0, -params.gravity_norm_mps2());
  if (params.faults().pedestrians().count() > 0) {
    scenario->pedestrians = Pedestrians(params.faults().pedestrians(),
                                        params.world().room_half_size_m(), params.duration_s(),
                                        params.seed());
  }
  TILTCAL_RETURN_IF_ERROR(TfStaticParamsAreValid(params));
  TILTCAL_RETURN_IF_ERROR(SetTiming(params, scenario));
  DropScans(params, scenario);
  return Status::Ok();
}

namespace {

using Clock = std::chrono::steady_clock;

// What a run did, for its summary line.
struct SimulateSummary {
  int num_imu_samples = 0;
  int num_scans = 0;
  uint64_t num_points = 0;
  uint64_t bag_bytes = 0;
  double raycast_seconds = 0.0;  // wall time in ray casting + serialization
  double total_seconds = 0.0;
};

// The units the IMU messages are published in (SimFaultParams).
imu::AccelUnit PublishedAccelUnit(const proto::SimFaultParams& faults) {
  return faults.imu_accel_unit() == proto::SimFaultParams::G ? imu::AccelUnit::kStandardGravity
                                                             : imu::AccelUnit::kMetresPerSecond2;
}
imu::GyroUnit PublishedGyroUnit(const proto::SimFaultParams& faults) {
  return faults.imu_gyro_unit() == proto::SimFaultParams::DEGPS
             ? imu::GyroUnit::kDegreesPerSecond
             : imu::GyroUnit::kRadiansPerSecond;
}

// The IMU: samples at rate_hz from the IMU clock's start, with
//   ω_m = ω_b + b_g + n_g,   f_m = C_wb^T (r̈_w − g_w) + b_a + n_a,
// white noise σ = density · sqrt(rate), bias random walk σ = density / sqrt(rate),
// from its own random stream. Every sample is simulated at its nominal time;
// the schedule (imu_schedule.h) gives its header stamp and whether it is
// written; the values are written in the units of params.faults (SI / factor).
class ImuSimulator {
 public:
  ImuSimulator(const proto::SimulateParams& params, const Scenario& scenario)
      : params_(params.imu()),
        scenario_(scenario),
        schedule_(MakeImuSchedule(scenario.num_imu_samples, params_.rate_hz(),
                                  scenario.imu_start_stamp_ns, params.faults(), params.seed())),
        rng_(params.seed(), kImuNoiseStream),
        rate_(params_.rate_hz()),
        gyro_sigma_(params_.gyro_noise_density_radps_sqrthz() * std::sqrt(rate_)),
        accel_sigma_(params_.accel_noise_density_mps2_sqrthz() * std::sqrt(rate_)),
        gyro_walk_(params_.gyro_bias_random_walk_radps2_sqrthz() / std::sqrt(rate_)),
        accel_walk_(params_.accel_bias_random_walk_mps3_sqrthz() / std::sqrt(rate_)),
        gyro_published_per_si_(1.0 / imu::ToSiFactor(PublishedGyroUnit(params.faults()))),
        accel_published_per_si_(1.0 / imu::ToSiFactor(PublishedAccelUnit(params.faults()))),
        gyro_bias_(ToEigen(params_.gyro_bias_radps())),
        accel_bias_(ToEigen(params_.accel_bias_mps2())),
        last_gyro_bias_(gyro_bias_),
        last_accel_bias_(accel_bias_),
        vibration_(params.faults().imu_vibration(), params.seed()) {
    DrawImuIntrinsics(params.faults(), params.seed(), &gyro_errors_, &accel_errors_);
    gyro_from_true_ = gyro_errors_.MeasuredFromTrue();
    accel_from_true_ = accel_errors_.MeasuredFromTrue();
  }

  // Simulates the samples stamped up to `stamp_ns` (all of them for
  // INT64_MAX) not yet simulated, and writes those the schedule keeps.
  Status WriteUpTo(int64_t stamp_ns, uint32_t connection, ros1::BagWriter* writer) {
    while (next_ < scenario_.num_imu_samples && schedule_.stamp_ns[next_] <= stamp_ns) {
      TILTCAL_RETURN_IF_ERROR(SimulateSample(next_++, connection, writer));
    }
    return Status::Ok();
  }

  double max_yaw_rate() const { return max_yaw_rate_; }
  int num_dropped() const { return schedule_.num_dropped; }
  // The biases of the last sample.
  const Eigen::Vector3d& last_gyro_bias() const { return last_gyro_bias_; }
  const Eigen::Vector3d& last_accel_bias() const { return last_accel_bias_; }
  const TriadErrors& gyro_errors() const { return gyro_errors_; }
  const TriadErrors& accel_errors() const { return accel_errors_; }
  const ImuVibration& vibration() const { return vibration_; }

 private:
  Eigen::Vector3d Gaussian3() {
    const double x = rng_.Gaussian(), y = rng_.Gaussian(), z = rng_.Gaussian();
    return Eigen::Vector3d(x, y, z);
  }

  Status SimulateSample(int i, uint32_t connection, ros1::BagWriter* writer) {
    const int64_t rel_ns = NominalImuStampNs(0, rate_, i);
    const double t = rel_ns * 1e-9;
    const ImuState s = scenario_.trajectory->Evaluate(t);
    max_yaw_rate_ = std::max(max_yaw_rate_, std::abs(s.yaw_rate_radps));
    // What the triads feel (frame b): the motion plus the vibration; then
    // what they read: K · that (imu_intrinsics.h), plus bias and noise.
    Eigen::Vector3d omega_felt = s.angular_velocity_b;
    Eigen::Vector3d force_felt =
        s.world_from_imu.transpose() * (s.acceleration_w - scenario_.gravity_w);
    vibration_.Add(t, s.moving_rate, &omega_felt, &force_felt);
    if (!gyro_errors_.IsIdentity()) omega_felt = gyro_from_true_ * omega_felt;
    if (!accel_errors_.IsIdentity()) force_felt = accel_from_true_ * force_felt;
    const Eigen::Vector3d omega = omega_felt + gyro_bias_ + gyro_sigma_ * Gaussian3();
    const Eigen::Vector3d force = force_felt + accel_bias_ + accel_sigma_ * Gaussian3();
    last_gyro_bias_ = gyro_bias_;
    last_accel_bias_ = accel_bias_;
    gyro_bias_ += gyro_walk_ * Gaussian3();
    accel_bias_ += accel_walk_ * Gaussian3();
    if (!schedule_.kept[i]) return Status::Ok();
    const int64_t stamp_ns = schedule_.stamp_ns[i];
    const double gyro_sigma = gyro_sigma_ * gyro_published_per_si_;
    const double accel_sigma = accel_sigma_ * accel_published_per_si_;
    if (!ros1::SerializeImu(static_cast<uint32_t>(i), stamp_ns, params_.frame_id(),
                            omega * gyro_published_per_si_, force * accel_published_per_si_,
                            gyro_sigma * gyro_sigma, accel_sigma * accel_sigma, &message_)) {
      return Status::Error("IMU stamp of sample " + std::to_string(i) + " is not a ROS time");
    }
    return writer->Write(connection, stamp_ns, message_);
  }

  const proto::SimImuParams& params_;
  const Scenario& scenario_;
  const ImuSchedule schedule_;
  Rng rng_;
  const double rate_;
  const double gyro_sigma_, accel_sigma_, gyro_walk_, accel_walk_;
  // Published value = SI value × this (1 in SI units).
  const double gyro_published_per_si_, accel_published_per_si_;
  Eigen::Vector3d gyro_bias_, accel_bias_;
  Eigen::Vector3d last_gyro_bias_, last_accel_bias_;
  const ImuVibration vibration_;
  TriadErrors gyro_errors_, accel_errors_;
  Eigen::Matrix3d gyro_from_true_, accel_from_true_;  // K_g, K_a
  int next_ = 0;
  double max_yaw_rate_ = 0.0;
  std::string message_;
};

// Frames of the truth: world a = the IMU frame at the first sample, the
// simulator's world w, the plane normal and the flat-ground gravity.
struct TruthFrames {
  TruthFrames(const proto::SimulateParams& params, const Scenario& scenario) {
    scenario.trajectory->Pose(0.0, &c_wb0, &r_wb0);
    c_aw = c_wb0.transpose();
    n_w = scenario.trajectory->NormalInWorld();
    const Eigen::Matrix3d c_vb =
        geometry::RotationFromEuler123Deg(ToEigen(params.rig().imu_rotation_in_vehicle_deg()));
    g_f = c_vb.transpose() * scenario.gravity_w;
    up_f = -g_f.normalized();
  }
  Eigen::Matrix3d c_wb0;
  Eigen::Vector3d r_wb0;
  Eigen::Matrix3d c_aw;                                    // C_aw = C_wb(0)^T
  Eigen::Vector3d n_w;                                     // ground normal in w
  const Eigen::Vector3d up_w = Eigen::Vector3d::UnitZ();  // level up in w
  Eigen::Vector3d g_f;                                     // gravity in b on flat ground
  Eigen::Vector3d up_f;
};

// The truth of one written scan with bag stamp `stamp_ns`.
void FillTruthScan(const Scenario& scenario, const TruthFrames& f, const SimulatedScan& scan,
                   int64_t start_ns, int64_t stamp_ns, proto::TruthScan* ts) {
  const Eigen::Matrix3d& c_bl = scenario.scan.imu_from_lidar_rotation;
  const Eigen::Vector3d& r_bl = scenario.scan.imu_from_lidar_translation;
  const int64_t true_rel_ns = scan.stamp_true_ns;
  const ImuState s = scenario.trajectory->Evaluate(true_rel_ns * 1e-9);
  const Eigen::Matrix3d c_wl = s.world_from_imu * c_bl;
  const Eigen::Vector3d r_wl = s.position_w + s.world_from_imu * r_bl;
  ts->set_stamp_ns(stamp_ns);
  ts->set_true_stamp_ns(start_ns + true_rel_ns);
  *ts->mutable_ground_normal_in_lidar() = ToProto(Eigen::Vector3d(c_wl.transpose() * f.n_w));
  ts->set_ground_height_m(f.n_w.dot(r_wl));  // the plane passes through the origin
  ts->set_inclination_deg(AngleDeg(f.n_w, f.up_w));
  *ts->mutable_world_from_imu() =
      RigidToProto(f.c_aw * s.world_from_imu, f.c_aw * (s.position_w - f.r_wb0));
  ts->set_vehicle_inclination_deg(AngleDeg(s.world_from_imu.transpose() * f.up_w, f.up_f));
  ts->set_num_points(scan.num_valid);
  ts->set_num_ground_points(scan.num_ground);
}

// The values the faults drew (only for the faults the scenario has, so a
// clean scenario's truth keeps its fields).
void FillFaultTruth(const proto::SimFaultParams& faults, const Scenario& scenario,
                    const ImuSimulator& imu, proto::SimulationTruth* truth) {
  if (faults.has_gyro_intrinsics()) *truth->mutable_gyro_intrinsics() = ToTruth(imu.gyro_errors());
  if (faults.has_accel_intrinsics()) {
    *truth->mutable_accel_intrinsics() = ToTruth(imu.accel_errors());
  }
  if (imu.vibration().enabled()) {
    *truth->mutable_imu_vibration_gyro_phase_rad() = ToProto(imu.vibration().gyro_phase_rad());
    *truth->mutable_imu_vibration_accel_phase_rad() = ToProto(imu.vibration().accel_phase_rad());
  }
  truth->set_num_scans_dropped(static_cast<uint32_t>(scenario.num_scans_dropped));
  truth->set_rolling_ground_phase_u_rad(scenario.rolling_phase_u_rad);
  truth->set_rolling_ground_phase_v_rad(scenario.rolling_phase_v_rad);
  for (const Pedestrian& person : scenario.pedestrians.people()) {
    proto::TruthPedestrian* t = truth->add_pedestrians();
    t->set_radius_m(person.radius_m);
    t->set_height_m(person.height_m);
    t->set_speed_mps(person.speed_mps);
    for (size_t j = 0; j < person.waypoints.size(); ++j) {
      t->add_waypoint_x_m(person.waypoints[j].x());
      t->add_waypoint_y_m(person.waypoints[j].y());
      t->add_arrival_s(person.arrival_s[j]);
    }
  }
}

// The sequence-level truth, after every scan is in.
void FillSequenceTruth(const proto::SimulateParams& params, const Scenario& scenario,
                       const TruthFrames& f, const ImuSimulator& imu,
                       proto::SimulationTruth* truth) {
  const auto& ip = params.imu();
  const ScanConfig& sc = scenario.scan;
  *truth->mutable_imu_from_lidar() =
      RigidToProto(sc.imu_from_lidar_rotation, sc.imu_from_lidar_translation);
  truth->set_time_offset_s(scenario.time_offset_ns * 1e-9);
  *truth->mutable_gravity_in_world() = ToProto(Eigen::Vector3d(f.c_aw * scenario.gravity_w));
  *truth->mutable_gravity_flat_in_imu() = ToProto(f.g_f);
  truth->set_imu_height_m(params.rig().imu_height_m());
  *truth->mutable_gyro_bias_radps() = ip.gyro_bias_radps();
  *truth->mutable_accel_bias_mps2() = ip.accel_bias_mps2();
  *truth->mutable_gyro_bias_last_radps() = ToProto(imu.last_gyro_bias());
  *truth->mutable_accel_bias_last_mps2() = ToProto(imu.last_accel_bias());
  *truth->mutable_ground_normal_in_world() = ToProto(f.n_w);
  truth->set_ground_roll_deg(params.ground_roll_deg());
  truth->set_ground_pitch_deg(params.ground_pitch_deg());
  truth->set_start_stamp_ns(scenario.imu_start_stamp_ns);
  *truth->mutable_ground_normal_in_world_a() = ToProto(Eigen::Vector3d(f.c_aw * f.n_w));
  truth->set_ground_offset_in_world_m(params.rig().imu_height_m());
  truth->set_lidar_model(sc.model.name);
  truth->set_num_imu_samples(static_cast<uint32_t>(scenario.num_imu_samples - imu.num_dropped()));
  truth->set_max_yaw_rate_radps(imu.max_yaw_rate());
  truth->set_mean_speed_mps(params.trajectory().speed_mps());
  truth->set_range_noise_m(params.lidar().range_noise_m());
  truth->set_gyro_noise_density_radps_sqrthz(ip.gyro_noise_density_radps_sqrthz());
  truth->set_accel_noise_density_mps2_sqrthz(ip.accel_noise_density_mps2_sqrthz());
  *truth->mutable_world_from_sim_world() = RigidToProto(f.c_aw, -f.c_aw * f.r_wb0);
  truth->set_inclination_deg(AngleDeg(f.n_w, f.up_w));
  truth->set_time_offset_ns(scenario.time_offset_ns);
  truth->set_imu_clock_shift_ns(scenario.imu_clock_shift_ns);
  if (params.has_faults()) *truth->mutable_faults() = params.faults();
  truth->set_num_imu_samples_dropped(static_cast<uint32_t>(imu.num_dropped()));
  FillFaultTruth(params.faults(), scenario, imu, truth);
}

// The rig a user would have measured: the true extrinsic with the errors of
// params.rig_file, C_meas = C(rotation_error_in_imu_deg) C_bl C(rotation_error_deg).
proto::Rig MakeRig(const proto::SimulateParams& params, const Scenario& scenario,
                   const TruthFrames& f) {
  const auto& rf = params.rig_file();
  const ScanConfig& sc = scenario.scan;
  proto::Rig rig;
  *rig.mutable_imu_from_lidar() = RigidToProto(
      geometry::RotationFromEuler123Deg(ToEigen(rf.rotation_error_in_imu_deg())) *
          sc.imu_from_lidar_rotation *
          geometry::RotationFromEuler123Deg(ToEigen(rf.rotation_error_deg())),
      sc.imu_from_lidar_translation + ToEigen(rf.translation_error_m()));
  rig.set_imu_height_m(params.rig().imu_height_m());
  rig.set_imu_topic(params.imu().topic());
  rig.set_lidar_topic(params.lidar().topic());
  rig.set_lidar_model(sc.model.name);
  if (rf.write_gravity_flat()) *rig.mutable_gravity_flat_in_imu() = ToProto(f.g_f);
  rig.set_gravity_reference(rf.gravity_reference());
  return rig;
}

// The sweeps, in batches: ray casting and serialization in worker threads
// (one random stream per sweep, so the bytes do not depend on the threads),
// writing in order on this thread, each after the IMU samples up to its
// record time (IMU first on ties).
class ScanWriter {
 public:
  ScanWriter(const proto::SimulateParams& params, const Scenario& scenario, unsigned threads)
      : params_(params),
        scenario_(scenario),
        threads_(threads),
        batch_(static_cast<int>(threads) * 2),
        messages_(batch_),
        scans_(batch_),
        ok_(batch_) {}

  Status WriteAll(ros1::BagWriter* writer, uint32_t lidar_conn, uint32_t imu_conn,
                  ImuSimulator* imu, const TruthFrames& frames, proto::SimulationTruth* truth,
                  std::ostream* progress, SimulateSummary* summary) {
    const int num_scans = scenario_.num_scans;
    for (int first = 0; first < num_scans; first += batch_) {
      const int count = std::min(batch_, num_scans - first);
      const auto t0 = Clock::now();
      SimulateBatch(first, count);
      summary->raycast_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
      for (int j = 0; j < count; ++j) {
        const int k = first + j;
        if (!scenario_.scan_kept[static_cast<size_t>(k)]) continue;
        const int64_t stamp = StampNs(scans_[j]);
        const int64_t record = scenario_.LidarRecordNs(scans_[j].stamp_true_ns);
        if (!ok_[j]) return Status::Error("scan " + std::to_string(k) + ": stamp is not a ROS time");
        TILTCAL_RETURN_IF_ERROR(imu->WriteUpTo(record, imu_conn, writer));
        TILTCAL_RETURN_IF_ERROR(writer->Write(lidar_conn, record, messages_[j]));
        summary->num_points += scans_[j].num_valid;
        FillTruthScan(scenario_, frames, scans_[j], scenario_.imu_start_stamp_ns, stamp,
                      truth->add_scans());
        if (progress != nullptr) {
          *progress << fmt::format("\rtiltcal_simulate: scan {} / {}{}", k + 1, num_scans,
                                   k + 1 == num_scans ? "\n" : "")
                    << std::flush;
        }
      }
    }
    return Status::Ok();
  }

 private:
  // The bag stamp of a sweep (LiDAR clock: IMU clock − τ, with the drift).
  int64_t StampNs(const SimulatedScan& scan) const {
    return scenario_.LidarStampNs(scan.stamp_true_ns);
  }

  // Simulates and serializes sweeps first .. first + count - 1.
  void SimulateBatch(int first, int count) {
    const auto& lp = params_.lidar();
    const bool ouster = scenario_.scan.model.kind == LidarModel::Kind::kOuster;
    const bool livox = scenario_.scan.model.kind == LidarModel::Kind::kLivox;
    auto work = [&](unsigned tid) {
      for (int j = static_cast<int>(tid); j < count; j += static_cast<int>(threads_)) {
        const int k = first + j;
        if (!scenario_.scan_kept[static_cast<size_t>(k)]) continue;  // left out, not simulated
        scans_[j] = SimulateSweep(scenario_.scan, *scenario_.trajectory, *scenario_.world,
                                  params_.seed(), k, &scenario_.pedestrians);
        ok_[j] = livox ? SerializeLivoxScan(scans_[j], static_cast<uint32_t>(k),
                                            StampNs(scans_[j]), lp.frame_id(), &messages_[j])
                       : SerializeScan(scans_[j], ouster, lp.append_surface_label(),
                                       static_cast<uint32_t>(k), StampNs(scans_[j]),
                                       lp.frame_id(), &messages_[j]);
        // Keep the counts; drop the points.
        scans_[j].points.clear();
        scans_[j].points.shrink_to_fit();
      }
    };
    std::vector<std::thread> pool;
    for (unsigned tid = 1; tid < threads_; ++tid) pool.emplace_back(work, tid);
    work(0);
    for (auto& th : pool) th.join();
  }

  const proto::SimulateParams& params_;
  const Scenario& scenario_;
  const unsigned threads_;
  const int batch_;
  std::vector<std::string> messages_;
  std::vector<SimulatedScan> scans_;
  std::vector<char> ok_;
};

void PrintSummary(std::ostream* log, const SimulateSummary& s) {
  if (log == nullptr) return;
  *log << fmt::format(
      "tiltcal_simulate: {} IMU samples, {} scans, {} points, {:.1f} MB bag; "
      "ray casting {:.2f} s, total {:.2f} s\n",
      s.num_imu_samples, s.num_scans, s.num_points, s.bag_bytes / 1e6, s.raycast_seconds,
      s.total_seconds);
}

}  // namespace

Status Run(const SimulatePaths& paths, const proto::SimulateParams& params, std::ostream* log) {
  const auto wall_start = Clock::now();
  if (paths.out_bag.empty() || paths.out_truth.empty()) {
    return Status::Error("--out_bag and --out_truth are required");
  }
  TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out_bag));
  TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out_truth));
  if (!paths.out_rig.empty()) TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out_rig));
  Scenario scenario;
  const Status built = BuildScenario(params, &scenario);
  if (!built.ok()) return paths.params.empty() ? built : built.WithContext(paths.params);
  unsigned threads = params.num_threads();
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  ros1::BagWriter writer;
  TILTCAL_RETURN_IF_ERROR(writer.Open(paths.out_bag, ToCompression(params.bag().compression()),
                                      params.bag().chunk_threshold_bytes(), threads));
  const ros1::MessageType& imu_type = ros1::ImuMessageType();
  const ros1::MessageType& cloud_type =
      scenario.scan.model.kind == LidarModel::Kind::kLivox ? ros1::LivoxCustomMsgMessageType()
                                                           : ros1::PointCloud2MessageType();
  const uint32_t imu_conn = writer.AddConnection(params.imu().topic(), imu_type.type,
                                                 imu_type.md5sum, imu_type.definition);
  const uint32_t lidar_conn = writer.AddConnection(params.lidar().topic(), cloud_type.type,
                                                   cloud_type.md5sum, cloud_type.definition);
  TILTCAL_RETURN_IF_ERROR(WriteTfStatic(params, scenario, &writer));

  SimulateSummary summary;
  ImuSimulator imu(params, scenario);
  const TruthFrames frames(params, scenario);
  proto::SimulationTruth truth;
  ScanWriter scans(params, scenario, threads);
  TILTCAL_RETURN_IF_ERROR(scans.WriteAll(&writer, lidar_conn, imu_conn, &imu, frames, &truth,
                                         cli::IsTerminalLog(log) ? log : nullptr, &summary));
  TILTCAL_RETURN_IF_ERROR(imu.WriteUpTo(INT64_MAX, imu_conn, &writer));
  TILTCAL_RETURN_IF_ERROR(writer.Close());

  *truth.mutable_provenance() =
      MakeProvenance("tiltcal_simulate", params, {}, paths.command_line);
  FillSequenceTruth(params, scenario, frames, imu, &truth);
  TILTCAL_RETURN_IF_ERROR(WriteTextProto(paths.out_truth, truth));
  if (!paths.out_rig.empty()) {
    TILTCAL_RETURN_IF_ERROR(WriteTextProto(paths.out_rig, MakeRig(params, scenario, frames)));
  }

  summary.num_imu_samples = scenario.num_imu_samples;
  summary.num_scans = scenario.num_scans - scenario.num_scans_dropped;
  summary.bag_bytes = writer.bytes_written();
  summary.total_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();
  PrintSummary(log, summary);
  return Status::Ok();
}

}  // namespace tiltcal::simulate
