#ifndef TILTCAL_STAGES_SIMULATE_SCAN_SIMULATOR_H_
#define TILTCAL_STAGES_SIMULATE_SCAN_SIMULATOR_H_

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "stages/simulate/lidar_model.h"
#include "stages/simulate/pedestrians.h"
#include "stages/simulate/trajectory.h"
#include "stages/simulate/world.h"

namespace tiltcal::simulate {

// One return (or, in organized Ouster clouds, one pixel) in the LiDAR frame
// at its own firing time.
struct ScanPoint {
  float x = 0, y = 0, z = 0;  // m, frame l at the firing time
  float intensity = 0;
  uint16_t ring = 0;
  uint16_t reflectivity = 0;  // Ouster
  float time_s = 0;           // Velodyne: firing time − stamp, s (float32 as the driver)
  uint32_t time_ns = 0;       // Ouster: column time − stamp; Livox: offset_time, ns
  uint8_t tag = 0;            // Livox: 0x01 for an injected noise point
  uint32_t range_mm = 0;      // Ouster: 0 = no return
  uint8_t label = 0;          // Surface
  bool valid = false;
};

struct SimulatedScan {
  // Stamp in true (IMU-clock) time, ns since the first IMU sample. The bag
  // stamp is this minus τ.
  int64_t stamp_true_ns = 0;
  // Velodyne: valid returns in firing order. Ouster: rows x columns pixels,
  // row-major (row = beam), invalid pixels included. Livox: every point in
  // time order, no return at the origin (as the drivers publish it).
  std::vector<ScanPoint> points;
  int rows = 1;
  int columns = 0;
  uint32_t num_valid = 0;
  uint32_t num_ground = 0;
};

struct ScanConfig {
  LidarModel model;
  double scan_rate_hz = 10.0;
  double min_range_m = 0.5;
  double max_range_m = 100.0;
  double range_noise_m = 0.01;
  bool velodyne_stamp_at_start = false;
  double first_scan_time_s = 0.1;  // true time of sweep 0's start
  // Livox: fraction of points replaced by noise (a random range along the
  // ray, tag 0x01: high confidence of noise by spatial position).
  double livox_noise_fraction = 0.0;
  // σ of the ground returns' height noise along the plane normal, m
  // (SimFaultParams.ground_roughness_m: grass), from the sweep's own
  // roughness stream (random.h).
  double ground_roughness_m = 0.0;
  Eigen::Matrix3d imu_from_lidar_rotation = Eigen::Matrix3d::Identity();  // C_bl
  Eigen::Vector3d imu_from_lidar_translation = Eigen::Vector3d::Zero();   // r_b^{lb}
};

// Livox: points per frame (point rate / frame rate).
int LivoxPoints(const ScanConfig& config);
// Start of sweep k in true time, ns since the first IMU sample.
int64_t SweepStartNs(const ScanConfig& config, int k);
// Duration of one sweep's firings, s (first to last firing).
double SweepSpanS(const ScanConfig& config);

// Ray-casts sweep k: every firing at its own time, from the LiDAR pose of
// that time (C_wl = C_wb C_bl, r_w^{lw} = r_w^{bw} + C_wb r_b^{lb}), with
// Gaussian range noise from `seed` (one random stream per sweep, so sweeps
// can be simulated in any order or in parallel with identical results).
// `pedestrians` (none when nullptr) are cast at each firing's time.
SimulatedScan SimulateSweep(const ScanConfig& config, const PlanarTrajectory& trajectory,
                            const World& world, uint64_t seed, int k,
                            const Pedestrians* pedestrians = nullptr);

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_SCAN_SIMULATOR_H_
