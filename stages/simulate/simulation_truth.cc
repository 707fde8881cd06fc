#include "stages/simulate/simulation_truth.h"

#include <cmath>

#include <Eigen/Geometry>

#include "common/geometry/angles.h"
#include "common/geometry/euler_angles.h"
#include "common/io/eigen_proto.h"

namespace tiltcal::simulate {
namespace {

using geometry::AngleBetweenDeg;

// The unit quaternion of `rotation` with w >= 0, the form written to disk.
proto::Rigid3 RigidToProto(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation) {
  Eigen::Quaterniond q(rotation);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  return ToProto(Rigid3d{q, translation});
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

}  // namespace

TruthFrames::TruthFrames(const proto::SimulateParams& params, const Scenario& scenario) {
    scenario.trajectory->Pose(0.0, &c_wb0, &r_wb0);
    c_aw = c_wb0.transpose();
    n_w = scenario.trajectory->NormalInWorld();
    const Eigen::Matrix3d c_vb =
        geometry::RotationFromEuler123Deg(ToEigen(params.rig().imu_rotation_in_vehicle_deg()));
    g_f = c_vb.transpose() * scenario.gravity_w;
    up_f = -g_f.normalized();
  }

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
  ts->set_inclination_deg(AngleBetweenDeg(f.n_w, f.up_w));
  *ts->mutable_world_from_imu() =
      RigidToProto(f.c_aw * s.world_from_imu, f.c_aw * (s.position_w - f.r_wb0));
  ts->set_vehicle_inclination_deg(AngleBetweenDeg(s.world_from_imu.transpose() * f.up_w, f.up_f));
  ts->set_num_points(scan.num_valid);
  ts->set_num_ground_points(scan.num_ground);
}

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
  truth->set_inclination_deg(AngleBetweenDeg(f.n_w, f.up_w));
  truth->set_time_offset_ns(scenario.time_offset_ns);
  truth->set_imu_clock_shift_ns(scenario.imu_clock_shift_ns);
  if (params.has_faults()) *truth->mutable_faults() = params.faults();
  truth->set_num_imu_samples_dropped(static_cast<uint32_t>(imu.num_dropped()));
  FillFaultTruth(params.faults(), scenario, imu, truth);
}

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

}  // namespace tiltcal::simulate
