#include "stages/simulate/scenario.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "common/geometry/angles.h"
#include "common/geometry/euler_angles.h"
#include "common/io/eigen_proto.h"
#include "stages/simulate/fault_params.h"
#include "stages/simulate/random.h"
#include "stages/simulate/tf_static_writer.h"

namespace tiltcal::simulate {

namespace {

using geometry::kRadPerDeg;
// Largest stamp a ROS time can hold.
constexpr int64_t kMaxRosTimeNs = 4294967295LL * 1000000000LL;

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

}  // namespace tiltcal::simulate
