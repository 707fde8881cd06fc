#include "stages/simulate/fault_params.h"

#include <utility>

#include <fmt/format.h>

#include "stages/simulate/imu_intrinsics.h"

namespace tiltcal::simulate {

Status SimFaultParamsAreValid(const proto::SimFaultParams& faults, double duration_s) {
  for (int g = 0; g < faults.imu_gaps_size(); ++g) {
    const proto::SimImuGap& gap = faults.imu_gaps(g);
    if (gap.duration_s() <= 0) {
      return Status::Error(fmt::format("field faults.imu_gaps[{}].duration_s = {} must be > 0", g,
                                       gap.duration_s()));
    }
    if (gap.start_s() >= duration_s) {
      return Status::Error(fmt::format(
          "field faults.imu_gaps[{}].start_s = {} is not before the end of the sequence "
          "(duration_s = {})",
          g, gap.start_s(), duration_s));
    }
  }
  TILTCAL_RETURN_IF_ERROR(
      SimTriadErrorsAreValid(faults.gyro_intrinsics(), "faults.gyro_intrinsics"));
  TILTCAL_RETURN_IF_ERROR(
      SimTriadErrorsAreValid(faults.accel_intrinsics(), "faults.accel_intrinsics"));
  const proto::SimImuVibration& vibration = faults.imu_vibration();
  if ((vibration.accel_amplitude_mps2() > 0 || vibration.gyro_amplitude_radps() > 0) &&
      vibration.frequency_hz() <= 0) {
    return Status::Error(
        "field faults.imu_vibration.frequency_hz must be > 0 with a vibration amplitude");
  }
  if (faults.rolling_ground_amplitude_m() > 0 && faults.rolling_ground_wavelength_m() <= 0) {
    return Status::Error(
        "field faults.rolling_ground_wavelength_m must be > 0 with rolling_ground_amplitude_m");
  }
  const proto::SimPedestrianParams& people = faults.pedestrians();
  if (people.count() > 0) {
    for (const auto& [value, name] : {std::pair{people.speed_mps(), "speed_mps"},
                                      std::pair{people.radius_m(), "radius_m"},
                                      std::pair{people.height_m(), "height_m"}}) {
      if (value <= 0) {
        return Status::Error(
            fmt::format("field faults.pedestrians.{} must be > 0 with a count", name));
      }
    }
  }
  return Status::Ok();
}

}  // namespace tiltcal::simulate
