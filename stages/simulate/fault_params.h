#ifndef TILTCAL_STAGES_SIMULATE_FAULT_PARAMS_H_
#define TILTCAL_STAGES_SIMULATE_FAULT_PARAMS_H_

#include "common/status.h"
#include "tiltcal/proto/simulate_params.pb.h"

namespace tiltcal::simulate {

// Checks what the schema bounds of `faults` cannot: every IMU gap has a
// positive duration and starts before `duration_s` (the scenario's); the
// triad errors' Vector3 components are within their bounds; a vibration
// amplitude has a frequency, a rolling ground a wavelength, pedestrians a
// speed, radius and height. The error names the field.
Status SimFaultParamsAreValid(const proto::SimFaultParams& faults, double duration_s);

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_FAULT_PARAMS_H_
