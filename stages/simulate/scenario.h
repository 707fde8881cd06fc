#ifndef TILTCAL_STAGES_SIMULATE_SCENARIO_H_
#define TILTCAL_STAGES_SIMULATE_SCENARIO_H_

#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "stages/simulate/pedestrians.h"
#include "stages/simulate/scan_simulator.h"
#include "stages/simulate/trajectory.h"
#include "stages/simulate/world.h"
#include "tiltcal/proto/simulate_params.pb.h"

namespace tiltcal::simulate {

// The scene, motion and sensors a params file describes (I/O-free; tests
// use it to evaluate the true trajectory).
struct Scenario {
  std::unique_ptr<PlanarTrajectory> trajectory;
  std::unique_ptr<World> world;
  ScanConfig scan;
  Eigen::Vector3d gravity_w;        // (0, 0, −g)
  int num_imu_samples = 0;
  int num_scans = 0;
  int64_t time_offset_ns = 0;       // τ in ns
  // IMU clock at the first IMU sample: start_stamp_ns, plus τ when the
  // LiDAR clock (IMU clock − τ) would otherwise be negative at a sweep.
  int64_t imu_start_stamp_ns = 0;
  int64_t imu_clock_shift_ns = 0;   // imu_start_stamp_ns − start_stamp_ns (0 or τ)
  // SimFaultParams.lidar_clock_drift_ppm.
  double lidar_clock_drift_ppm = 0.0;
  // Per sweep: false when SimFaultParams.lidar_drop_fraction leaves it out.
  std::vector<bool> scan_kept;
  int num_scans_dropped = 0;
  // SimFaultParams.pedestrians (empty without).
  Pedestrians pedestrians;
  // SimFaultParams.rolling_ground_* phases φ_u, φ_v, rad (0 without).
  double rolling_phase_u_rad = 0.0, rolling_phase_v_rad = 0.0;

  // The LiDAR-clock stamp of true time `true_rel_ns` (ns since the first IMU
  // sample): imu_start_stamp_ns + t + round(t · drift_ppm · 1e-6) − τ.
  int64_t LidarStampNs(int64_t true_rel_ns) const;
  // The bag's record time of that sweep: the recorder's clock, which is the
  // IMU's: LidarStampNs without the drift term (the stamp when no drift).
  int64_t LidarRecordNs(int64_t true_rel_ns) const;
};

// Checks the params beyond their schema bounds (ranges, room size, sensor
// above the ground, stamps representable, the faults: fault_params.h) and
// builds the scenario.
Status BuildScenario(const proto::SimulateParams& params, Scenario* scenario);

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_SCENARIO_H_
