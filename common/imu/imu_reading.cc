#include "common/imu/imu_reading.h"

#include <cmath>
#include <string>

namespace tiltcal::imu {

Status ValidateImuReadings(const std::vector<ImuReading>& samples) {
  if (samples.empty()) return Status::Error("no IMU samples");
  for (size_t i = 0; i < samples.size(); ++i) {
    const ImuReading& s = samples[i];
    if (!std::isfinite(s.time_s) || !s.angular_velocity_radps.allFinite() ||
        !s.linear_acceleration_mps2.allFinite()) {
      return Status::Error("IMU sample " + std::to_string(i) + ": non-finite value");
    }
    if (i > 0 && !(s.time_s > samples[i - 1].time_s)) {
      return Status::Error("IMU sample " + std::to_string(i) + ": time " +
                           std::to_string(s.time_s) + " s does not increase");
    }
  }
  return Status::Ok();
}

}  // namespace tiltcal::imu
