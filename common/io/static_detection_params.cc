#include "common/io/static_detection_params.h"

namespace tiltcal {

imu::StaticDetectionOptions ToStaticDetectionOptions(const proto::StaticDetectionParams& params) {
  imu::StaticDetectionOptions options;
  options.window_s = params.window_s();
  options.hop_s = params.hop_s();
  options.max_gyro_std_radps = params.max_gyro_std_radps();
  options.max_accel_std_mps2 = params.max_accel_std_mps2();
  options.max_gyro_mean_radps = params.max_gyro_mean_radps();
  options.min_duration_s = params.min_duration_s();
  options.low_pass.cutoff_hz = params.low_pass().cutoff_hz();
  options.low_pass.span_s = params.low_pass().span_s();
  options.low_pass.max_gap_s = params.low_pass().max_gap_s();
  return options;
}

}  // namespace tiltcal
