#include "stages/simulate/simulate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include <Eigen/Geometry>

#include "common/io/provenance.h"
#include "common/io/text_proto.h"
#include "common/geometry/euler_angles.h"
#include "stages/simulate/point_cloud_layout.h"
#include "stages/simulate/random.h"
#include "stages/simulate/ros1_bag_writer.h"
#include "stages/simulate/ros1_messages.h"
#include "tiltcal/proto/rig.pb.h"

namespace tiltcal::simulate {

namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kRadToDeg = 180.0 / M_PI;
// Random stream of the IMU noise and of the random obstacles.
constexpr uint64_t kImuStream = 0;
constexpr uint64_t kWorldStream = 1;
// Largest stamp a ROS time can hold.
constexpr int64_t kMaxRosTimeNs = 4294967295LL * 1000000000LL;

Eigen::Vector3d ToEigen(const proto::Vector3& v) { return Eigen::Vector3d(v.x(), v.y(), v.z()); }

void SetVector(const Eigen::Vector3d& v, proto::Vector3* out) {
  out->set_x(v.x());
  out->set_y(v.y());
  out->set_z(v.z());
}

void SetRigid(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation,
              proto::Rigid3* out) {
  Eigen::Quaterniond q(rotation);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  out->mutable_rotation()->set_w(q.w());
  out->mutable_rotation()->set_x(q.x());
  out->mutable_rotation()->set_y(q.y());
  out->mutable_rotation()->set_z(q.z());
  SetVector(translation, out->mutable_translation());
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kRadToDeg;
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

Ros1BagWriter::Compression ToCompression(proto::SimBagParams::Compression c) {
  switch (c) {
    case proto::SimBagParams::BZ2: return Ros1BagWriter::Compression::kBz2;
    case proto::SimBagParams::LZ4: return Ros1BagWriter::Compression::kLz4;
    default: return Ros1BagWriter::Compression::kNone;
  }
}

}  // namespace

Status BuildScenario(const proto::SimulateParams& params, Scenario* scenario) {
  const auto& tp = params.trajectory();
  const auto& rig = params.rig();
  const auto& lp = params.lidar();
  const auto& wp = params.world();

  TrajectoryConfig tc;
  tc.shape = tp.shape() == proto::SimTrajectoryParams::CIRCLE
                 ? TrajectoryConfig::Shape::kCircle
                 : TrajectoryConfig::Shape::kFigureEight;
  tc.length_m = tp.length_m();
  tc.width_m = tp.width_m();
  tc.speed_mps = tp.speed_mps();
  tc.static_start_s = tp.static_start_s();
  tc.ramp_s = tp.ramp_s();
  tc.vibration_roll_rad = tp.vibration_roll_deg() * kDegToRad;
  tc.vibration_pitch_rad = tp.vibration_pitch_deg() * kDegToRad;
  tc.vibration_frequency_hz = tp.vibration_frequency_hz();
  tc.heading_rad = tp.heading_deg() * kDegToRad;
  tc.max_yaw_rate_radps = tp.max_yaw_rate_radps();
  tc.ground_roll_rad = params.ground_roll_deg() * kDegToRad;
  tc.ground_pitch_rad = params.ground_pitch_deg() * kDegToRad;
  tc.imu_height_m = rig.imu_height_m();
  tc.vehicle_from_imu = geometry::RotationFromEuler123Deg(ToEigen(rig.imu_rotation_in_vehicle_deg()));
  if ((tc.vibration_roll_rad > 0 || tc.vibration_pitch_rad > 0) &&
      tc.vibration_frequency_hz <= 0) {
    return Status::Error("field trajectory.vibration_frequency_hz must be > 0 with a vibration");
  }
  scenario->trajectory = std::make_unique<PlanarTrajectory>(tc);
  const PlanarTrajectory& trajectory = *scenario->trajectory;

  // The track must fit in the room.
  const double half = wp.room_half_size_m();
  const Eigen::Vector2d pmin = trajectory.PathMin(), pmax = trajectory.PathMax();
  const double extent = std::max(pmin.cwiseAbs().maxCoeff(), pmax.cwiseAbs().maxCoeff());
  if (wp.wall_height_m() > 0 && extent + 2.0 > half) {
    return Status::Error("field world.room_half_size_m = " + std::to_string(half) +
                         " leaves no room for the track (extent " + std::to_string(extent) +
                         " m + 2 m)");
  }

  // LiDAR model and timing.
  ScanConfig& sc = scenario->scan;
  switch (lp.model()) {
    case proto::SimLidarParams::VLP_16: sc.model = Vlp16Model(); break;
    case proto::SimLidarParams::VLP_32C: sc.model = Vlp32cModel(); break;
    case proto::SimLidarParams::OS1_32: {
      const uint32_t columns = lp.ouster_columns() == 0 ? 1024 : lp.ouster_columns();
      if (columns != 512 && columns != 1024 && columns != 2048) {
        return Status::Error("field lidar.ouster_columns = " + std::to_string(columns) +
                             " must be 512, 1024 or 2048");
      }
      sc.model = Os132Model(static_cast<int>(columns));
      break;
    }
    default: return Status::Error("field lidar.model must be VLP_16, VLP_32C or OS1_32");
  }
  if (lp.max_range_m() <= lp.min_range_m()) {
    return Status::Error("field lidar.max_range_m must exceed lidar.min_range_m");
  }
  sc.scan_rate_hz = lp.scan_rate_hz();
  sc.min_range_m = lp.min_range_m();
  sc.max_range_m = lp.max_range_m();
  sc.range_noise_m = lp.range_noise_m();
  sc.velodyne_stamp_at_start = lp.velodyne_stamp_at_start();
  sc.first_scan_time_s = lp.first_scan_time_s();
  sc.imu_from_lidar_rotation = geometry::RotationFromEuler123Deg(ToEigen(rig.lidar_rotation_in_imu_deg()));
  sc.imu_from_lidar_translation = ToEigen(rig.lidar_translation_in_imu_m());

  // The LiDAR must be above the ground (checked at the start pose).
  {
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
  }

  scenario->world = std::make_unique<World>(trajectory.NormalInWorld(), half, wp.wall_height_m());
  for (const auto& b : wp.boxes()) {
    const double z = scenario->world->GroundZ(b.center_x_m(), b.center_y_m());
    scenario->world->AddBox({b.center_x_m() - 0.5 * b.size_x_m(), b.center_x_m() + 0.5 * b.size_x_m(),
                             b.center_y_m() - 0.5 * b.size_y_m(), b.center_y_m() + 0.5 * b.size_y_m(),
                             z + b.height_m()});
  }
  for (const auto& p : wp.pillars()) {
    const double z = scenario->world->GroundZ(p.center_x_m(), p.center_y_m());
    scenario->world->AddPillar({p.center_x_m(), p.center_y_m(), p.radius_m(), z + p.height_m()});
  }
  AddRandomObstacles(wp, trajectory, params.seed(), scenario->world.get());

  scenario->gravity_w = Eigen::Vector3d(0.0, 0.0, -params.gravity_norm_mps2());
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
  scenario->time_offset_ns = std::llround(rig.time_offset_s() * 1e9);

  // Every stamp must be a valid ROS time (LiDAR stamps are true − τ).
  const int64_t start = params.start_stamp_ns();
  if (start + SweepStartNs(sc, 0) - scenario->time_offset_ns < 0 ||
      start + duration_ns + std::abs(scenario->time_offset_ns) > kMaxRosTimeNs) {
    return Status::Error("field start_stamp_ns = " + std::to_string(start) +
                         " gives stamps outside the ROS time range with this duration and "
                         "rig.time_offset_s");
  }
  return Status::Ok();
}

Status Run(const proto::SimulateParams& params, const SimulateOutputs& outputs,
           SimulateSummary* summary) {
  const auto wall_start = std::chrono::steady_clock::now();
  Scenario scenario;
  TILTCAL_RETURN_IF_ERROR(BuildScenario(params, &scenario));
  const PlanarTrajectory& trajectory = *scenario.trajectory;
  const ScanConfig& sc = scenario.scan;
  const auto& ip = params.imu();
  const auto& lp = params.lidar();
  const int64_t start_ns = params.start_stamp_ns();
  const bool ouster = sc.model.kind == LidarModel::Kind::kOuster;

  unsigned threads = params.num_threads();
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  Ros1BagWriter writer;
  TILTCAL_RETURN_IF_ERROR(writer.Open(outputs.bag_path, ToCompression(params.bag().compression()),
                                      params.bag().chunk_threshold_bytes(), threads));
  const RosMessageType& imu_type = ImuMessageType();
  const RosMessageType& cloud_type = PointCloud2MessageType();
  const uint32_t imu_conn =
      writer.AddConnection(ip.topic(), imu_type.type, imu_type.md5sum, imu_type.definition);
  const uint32_t lidar_conn =
      writer.AddConnection(lp.topic(), cloud_type.type, cloud_type.md5sum, cloud_type.definition);

  // IMU model: ω_m = ω_b + b_g + n_g, f_m = C_wb^T (r̈_w − g_w) + b_a + n_a,
  // white noise σ = density · sqrt(rate), bias random walk σ = density / sqrt(rate).
  Rng imu_rng(params.seed(), kImuStream);
  const double rate = ip.rate_hz();
  const double gyro_sigma = ip.gyro_noise_density_radps_sqrthz() * std::sqrt(rate);
  const double accel_sigma = ip.accel_noise_density_mps2_sqrthz() * std::sqrt(rate);
  const double gyro_walk = ip.gyro_bias_random_walk_radps2_sqrthz() / std::sqrt(rate);
  const double accel_walk = ip.accel_bias_random_walk_mps3_sqrthz() / std::sqrt(rate);
  Eigen::Vector3d gyro_bias = ToEigen(ip.gyro_bias_radps());
  Eigen::Vector3d accel_bias = ToEigen(ip.accel_bias_mps2());
  Eigen::Vector3d last_gyro_bias = gyro_bias, last_accel_bias = accel_bias;
  auto gaussian3 = [&]() {
    const double x = imu_rng.Gaussian(), y = imu_rng.Gaussian(), z = imu_rng.Gaussian();
    return Eigen::Vector3d(x, y, z);
  };
  int next_imu = 0;
  std::string message;
  double max_yaw_rate = 0.0;
  auto imu_stamp_ns = [&](int i) {
    return start_ns + std::llround(static_cast<double>(i) * 1e9 / rate);
  };
  auto write_imu = [&](int i) -> Status {
    const int64_t rel_ns = imu_stamp_ns(i) - start_ns;
    const ImuState s = trajectory.Evaluate(rel_ns * 1e-9);
    max_yaw_rate = std::max(max_yaw_rate, std::abs(s.yaw_rate_radps));
    const Eigen::Vector3d omega = s.angular_velocity_b + gyro_bias + gyro_sigma * gaussian3();
    const Eigen::Vector3d force = s.world_from_imu.transpose() *
                                      (s.acceleration_w - scenario.gravity_w) +
                                  accel_bias + accel_sigma * gaussian3();
    last_gyro_bias = gyro_bias;
    last_accel_bias = accel_bias;
    gyro_bias += gyro_walk * gaussian3();
    accel_bias += accel_walk * gaussian3();
    if (!SerializeImu(static_cast<uint32_t>(i), imu_stamp_ns(i), ip.frame_id(), omega, force,
                      gyro_sigma * gyro_sigma, accel_sigma * accel_sigma, &message)) {
      return Status::Error("IMU stamp of sample " + std::to_string(i) + " is not a ROS time");
    }
    return writer.Write(imu_conn, imu_stamp_ns(i), message);
  };
  // Truth.
  proto::SimulationTruth truth;
  Eigen::Matrix3d c_wb0;
  Eigen::Vector3d r_wb0;
  trajectory.Pose(0.0, &c_wb0, &r_wb0);
  const Eigen::Matrix3d c_aw = c_wb0.transpose();
  const Eigen::Vector3d n_w = trajectory.NormalInWorld();
  const Eigen::Vector3d up_w = Eigen::Vector3d::UnitZ();
  const Eigen::Matrix3d c_vb = geometry::RotationFromEuler123Deg(ToEigen(params.rig().imu_rotation_in_vehicle_deg()));
  const Eigen::Vector3d g_f = c_vb.transpose() * scenario.gravity_w;
  const Eigen::Vector3d up_f = -g_f.normalized();
  const Eigen::Matrix3d& c_bl = sc.imu_from_lidar_rotation;
  const Eigen::Vector3d& r_bl = sc.imu_from_lidar_translation;

  // Scans in batches: ray casting and serialization in worker threads (one
  // random stream per sweep, so the result does not depend on the threads),
  // writing in order on this thread.
  const int batch = static_cast<int>(threads) * 2;
  const int num_scans = scenario.num_scans;
  const uint64_t seed = params.seed();
  std::vector<std::string> messages(batch);
  std::vector<SimulatedScan> scans(batch);
  std::vector<char> ok(batch);
  double raycast_seconds = 0.0;
  uint64_t num_points = 0;
  const int64_t tau_ns = scenario.time_offset_ns;

  for (int first = 0; first < num_scans; first += batch) {
    const int count = std::min(batch, num_scans - first);
    const auto t0 = std::chrono::steady_clock::now();
    auto work = [&](unsigned tid) {
      for (int j = static_cast<int>(tid); j < count; j += static_cast<int>(threads)) {
        const int k = first + j;
        scans[j] = SimulateSweep(sc, trajectory, *scenario.world, seed, k);
        const int64_t stamp = start_ns + scans[j].stamp_true_ns - tau_ns;
        ok[j] = SerializeScan(scans[j], ouster, lp.append_surface_label(), static_cast<uint32_t>(k),
                              stamp, lp.frame_id(), &messages[j]);
        // Keep the counts; drop the points.
        scans[j].points.clear();
        scans[j].points.shrink_to_fit();
      }
    };
    std::vector<std::thread> pool;
    for (unsigned tid = 1; tid < threads; ++tid) pool.emplace_back(work, tid);
    work(0);
    for (auto& th : pool) th.join();
    raycast_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    for (int j = 0; j < count; ++j) {
      const int k = first + j;
      const SimulatedScan& scan = scans[j];
      const int64_t stamp = start_ns + scan.stamp_true_ns - tau_ns;
      if (!ok[j]) return Status::Error("scan " + std::to_string(k) + ": stamp is not a ROS time");
      // IMU samples up to this record time go first (IMU first on ties).
      while (next_imu < scenario.num_imu_samples && imu_stamp_ns(next_imu) <= stamp) {
        TILTCAL_RETURN_IF_ERROR(write_imu(next_imu++));
      }
      TILTCAL_RETURN_IF_ERROR(writer.Write(lidar_conn, stamp, messages[j]));
      num_points += scan.num_valid;

      proto::TruthScan* ts = truth.add_scans();
      const int64_t true_rel_ns = scan.stamp_true_ns;
      const ImuState s = trajectory.Evaluate(true_rel_ns * 1e-9);
      const Eigen::Matrix3d c_wl = s.world_from_imu * c_bl;
      const Eigen::Vector3d r_wl = s.position_w + s.world_from_imu * r_bl;
      ts->set_stamp_ns(stamp);
      ts->set_true_stamp_ns(start_ns + true_rel_ns);
      SetVector(c_wl.transpose() * n_w, ts->mutable_ground_normal_in_lidar());
      ts->set_ground_height_m(n_w.dot(r_wl));  // the plane passes through the origin
      ts->set_inclination_deg(AngleDeg(n_w, up_w));
      SetRigid(c_aw * s.world_from_imu, c_aw * (s.position_w - r_wb0),
               ts->mutable_world_from_imu());
      ts->set_vehicle_inclination_deg(AngleDeg(s.world_from_imu.transpose() * up_w, up_f));
      ts->set_num_points(scan.num_valid);
      ts->set_num_ground_points(scan.num_ground);
      if (outputs.progress) outputs.progress(k + 1, num_scans);
    }
  }
  while (next_imu < scenario.num_imu_samples) TILTCAL_RETURN_IF_ERROR(write_imu(next_imu++));
  TILTCAL_RETURN_IF_ERROR(writer.Close());

  // Truth, sequence level.
  *truth.mutable_provenance() = MakeProvenance("tiltcal_simulate", params, {},
                                               outputs.command_line);
  SetRigid(c_bl, r_bl, truth.mutable_imu_from_lidar());
  truth.set_time_offset_s(tau_ns * 1e-9);
  SetVector(c_aw * scenario.gravity_w, truth.mutable_gravity_in_world());
  SetVector(g_f, truth.mutable_gravity_flat_in_imu());
  truth.set_imu_height_m(params.rig().imu_height_m());
  *truth.mutable_gyro_bias_radps() = ip.gyro_bias_radps();
  *truth.mutable_accel_bias_mps2() = ip.accel_bias_mps2();
  SetVector(last_gyro_bias, truth.mutable_gyro_bias_last_radps());
  SetVector(last_accel_bias, truth.mutable_accel_bias_last_mps2());
  SetVector(n_w, truth.mutable_ground_normal_in_world());
  truth.set_ground_roll_deg(params.ground_roll_deg());
  truth.set_ground_pitch_deg(params.ground_pitch_deg());
  truth.set_start_stamp_ns(start_ns);
  SetVector(c_aw * n_w, truth.mutable_ground_normal_in_world_a());
  truth.set_ground_offset_in_world_m(params.rig().imu_height_m());
  truth.set_lidar_model(sc.model.name);
  truth.set_num_imu_samples(static_cast<uint32_t>(scenario.num_imu_samples));
  truth.set_max_yaw_rate_radps(max_yaw_rate);
  truth.set_mean_speed_mps(params.trajectory().speed_mps());
  truth.set_range_noise_m(lp.range_noise_m());
  truth.set_gyro_noise_density_radps_sqrthz(ip.gyro_noise_density_radps_sqrthz());
  truth.set_accel_noise_density_mps2_sqrthz(ip.accel_noise_density_mps2_sqrthz());
  SetRigid(c_aw, -c_aw * r_wb0, truth.mutable_world_from_sim_world());
  truth.set_inclination_deg(AngleDeg(n_w, up_w));
  TILTCAL_RETURN_IF_ERROR(WriteTextProto(outputs.truth_path, truth));

  if (!outputs.rig_path.empty()) {
    const auto& rf = params.rig_file();
    proto::Rig rig;
    SetRigid(c_bl * geometry::RotationFromEuler123Deg(ToEigen(rf.rotation_error_deg())),
             r_bl + ToEigen(rf.translation_error_m()), rig.mutable_imu_from_lidar());
    rig.set_imu_height_m(params.rig().imu_height_m());
    rig.set_imu_topic(ip.topic());
    rig.set_lidar_topic(lp.topic());
    rig.set_lidar_model(sc.model.name);
    if (rf.write_gravity_flat()) SetVector(g_f, rig.mutable_gravity_flat_in_imu());
    rig.set_gravity_reference(rf.gravity_reference());
    TILTCAL_RETURN_IF_ERROR(WriteTextProto(outputs.rig_path, rig));
  }

  if (summary != nullptr) {
    summary->num_imu_samples = scenario.num_imu_samples;
    summary->num_scans = num_scans;
    summary->num_points = num_points;
    summary->bag_bytes = writer.bytes_written();
    summary->raycast_seconds = raycast_seconds;
    summary->total_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  }
  return Status::Ok();
}

}  // namespace tiltcal::simulate
