#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_IMU_STATIC_NOISE_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_IMU_STATIC_NOISE_H_

// The IMU's noise at rest (docs/design.md §11). Over the static start the
// true angular velocity is zero and the specific force constant, so the
// readings' scatter about their mean is their noise, which no spline
// absorbs. Low-passed readings (imu_vibration.h) keep their in-band noise,
// and the spline, which follows that band, fits much of it: their residuals'
// variance components understate the noise. Measured at rest instead, per
// sensor:
//   v = sum_i |x_i - mean(x)|^2 / (3 (n - 1))      (per axis, pooled)
//   factor = v / sigma^2 * low_pass_correlation
// sigma the residuals' model sigma (imu_noise's / sqrt(m)) and
// low_pass_correlation LowPassCorrelation (imu_vibration.h): the
// white-equivalent variance factor of the readings, comparable with a
// variance component times its correlation, s_k tau_k
// (variance_components.h), of which it is the floor.

#include <vector>

#include "common/imu/imu_reading.h"

namespace tiltcal::calibrate {

struct ImuStaticNoise {
  int samples = 0;            // readings in [begin_s, end_s]
  double gyro_factor = 0.0;   // 0: fewer than kMinStaticNoiseSamples
  double accel_factor = 0.0;
};

constexpr int kMinStaticNoiseSamples = 10;

// readings: time order; [begin_s, end_s] the static start.
ImuStaticNoise MeasureImuStaticNoise(const std::vector<imu::ImuReading>& readings, double begin_s,
                                     double end_s, double gyro_sigma_radps,
                                     double accel_sigma_mps2, double low_pass_correlation);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_IMU_STATIC_NOISE_H_
