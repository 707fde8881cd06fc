#include "common/imu/imu_initialisation.h"

#include <algorithm>
#include <string>

#include "common/imu/gyro_integrator.h"

namespace tiltcal::imu {

Status InitialiseImu(const std::vector<ImuReading>& samples,
                     const ImuInitialisationOptions& options, ImuInitialisation* out) {
  TILTCAL_RETURN_IF_ERROR(ValidateImuReadings(samples));
  *out = ImuInitialisation();
  out->static_start = DetectStaticStart(samples, options.static_detection);

  size_t begin = 0, end = 0;
  if (out->static_start.found) {
    out->from_static_start = true;
    begin = out->static_start.begin_index;
    end = out->static_start.end_index;
    out->gyro_bias_radps = out->static_start.mean_gyro_radps;
  } else {
    const double end_s = samples.front().time_s + options.fallback_window_s;
    while (end < samples.size() && samples[end].time_s < end_s) ++end;
    end = std::max<size_t>(end, 1);
  }

  // Rotation-compensated mean specific force in a: at rest (or on average over
  // a window with zero mean acceleration) it equals −g_a.
  const GyroIntegrator integrator(samples, out->gyro_bias_radps);
  Eigen::Vector3d mean_f = Eigen::Vector3d::Zero();
  for (size_t i = begin; i < end; ++i) {
    mean_f += integrator.Rotation(samples[i].time_s) * samples[i].linear_acceleration_mps2;
  }
  mean_f /= static_cast<double>(end - begin);
  const double norm = mean_f.norm();
  if (!(norm > 1e-6)) {
    return Status::Error("IMU samples " + std::to_string(begin) + ".." +
                         std::to_string(end - 1) +
                         ": mean specific force is zero; cannot find gravity");
  }
  out->gravity_in_world_mps2 = -options.gravity_norm_mps2 * mean_f / norm;
  out->accel_norm_mismatch_mps2 = norm - options.gravity_norm_mps2;
  out->averaging_begin_s = samples[begin].time_s;
  out->averaging_end_s = samples[end - 1].time_s;
  out->num_samples_averaged = static_cast<int>(end - begin);
  return Status::Ok();
}

}  // namespace tiltcal::imu
