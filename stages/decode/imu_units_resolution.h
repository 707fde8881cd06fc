#ifndef TILTCAL_STAGES_DECODE_IMU_UNITS_RESOLUTION_H_
#define TILTCAL_STAGES_DECODE_IMU_UNITS_RESOLUTION_H_

// The decode stage's decision on the units and the sign of a bag's IMU, so
// that imu.binpb is always in m/s² and rad/s: the rig's statement
// (imu_accel_unit, imu_gyro_unit) checked against what the readings show
// (common/imu/imu_units.h), or, for AUTO, what they show.

#include <string>
#include <vector>

#include "common/imu/imu_reading.h"
#include "common/status.h"
#include "tiltcal/proto/decode_params.pb.h"
#include "tiltcal/proto/rig.pb.h"

namespace tiltcal::decode {

// Where the readings and the statement come from, for the messages.
struct ImuUnitsSources {
  std::string bag;
  std::string rig_path;  // "" = no rig: both units AUTO, the sign unchecked
};

struct ImuUnitsResolution {
  double accel_to_si = 1.0;  // multiplies the published specific force
  double gyro_to_si = 1.0;   // multiplies the published angular velocity
  // One sentence per decision (accelerometer unit, gyro unit, sign): what
  // was decided, from what evidence, what was done. For the log and the
  // provenance of imu.binpb.
  std::vector<std::string> notes;
  // The notes a user must not miss (a specific force that points down at
  // rest against the rig's rotation); also in `notes`.
  std::vector<std::string> warnings;
};

// Decides the units and checks the sign. Errors, one line each naming the
// file: a stated unit the readings contradict (naming both), readings that
// fit neither unit (naming the value), a specific force at rest pointing
// away from the rig's gravity_flat_in_imu by more than
// max_rest_force_angle_from_up_deg. `published`: valid readings (strictly
// increasing times) as the bag holds them.
Status ResolveImuUnits(const std::vector<imu::ImuReading>& published, const proto::Rig& rig,
                       const ImuUnitsSources& sources, const proto::ImuUnitsParams& params,
                       ImuUnitsResolution* resolution);

}  // namespace tiltcal::decode

#endif  // TILTCAL_STAGES_DECODE_IMU_UNITS_RESOLUTION_H_
