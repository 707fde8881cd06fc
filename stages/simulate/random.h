#ifndef TILTCAL_STAGES_SIMULATE_RANDOM_H_
#define TILTCAL_STAGES_SIMULATE_RANDOM_H_

#include <cstdint>

namespace tiltcal::simulate {

// A small, portable random generator (xoshiro256** seeded through
// splitmix64) with its own normal sampler, so a seed gives the same numbers
// with every compiler and standard library (std:: distributions do not).
// The random streams of one scenario, one per use, so that switching one
// use on or off leaves every other stream's numbers unchanged.
inline constexpr uint64_t kImuNoiseStream = 0;       // IMU white noise and bias walk
inline constexpr uint64_t kWorldStream = 1;          // random boxes and pillars
inline constexpr uint64_t kImuStampJitterStream = 2;  // SimFaultParams.imu_stamp_jitter_s
inline constexpr uint64_t kImuDropStream = 3;         // SimFaultParams.imu_drop_fraction
inline constexpr uint64_t kImuIntrinsicsStream = 4;   // SimFaultParams.*_intrinsics bounds
inline constexpr uint64_t kImuVibrationStream = 5;    // SimFaultParams.imu_vibration phases
inline constexpr uint64_t kLidarDropStream = 6;       // SimFaultParams.lidar_drop_fraction
inline constexpr uint64_t kRollingGroundStream = 7;   // SimFaultParams.rolling_ground_* phases
inline constexpr uint64_t kPedestrianStream = 8;      // SimFaultParams.pedestrians paths
inline constexpr uint64_t kSweepStreamBase = 1000;    // + k: range noise of sweep k
// + k: SimFaultParams.ground_roughness_m of sweep k
inline constexpr uint64_t kGroundRoughnessStreamBase = uint64_t{1} << 32;

class Rng {
 public:
  // Streams with different `stream` values are independent for one seed
  // (one stream per scan lets scans be simulated in parallel).
  explicit Rng(uint64_t seed, uint64_t stream = 0);

  uint64_t NextU64();
  // Uniform in [0, 1).
  double Uniform();
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Standard normal (Marsaglia polar method).
  double Gaussian();

 private:
  uint64_t s_[4];
  bool have_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_RANDOM_H_
