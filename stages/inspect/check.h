#ifndef TILTCAL_STAGES_INSPECT_CHECK_H_
#define TILTCAL_STAGES_INSPECT_CHECK_H_

#include <ostream>
#include <string>

#include "common/status.h"
#include "tiltcal/proto/check_params.pb.h"

namespace tiltcal::inspect {

struct CheckPaths {
  std::string bag;  // required: a ROS1 bag
  std::string rig;  // optional: rig.txtpb (topics, C_bl for "up", imu_height_m)
};

// The cross-field rules of CheckParams beyond its schema bounds; the message
// names the field.
Status CheckParamsAreValid(const proto::CheckParams& params);

// `tiltcal_inspect check`: reads the bag once and writes the pre-flight
// report (stages/inspect/check_report.h) to `out`. Returns an error naming
// the bag when it cannot be read, and "<bag>: cannot be calibrated: <reasons>"
// when the report's verdict is negative (after the report is written).
Status RunCheck(const CheckPaths& paths, const proto::CheckParams& params, std::ostream& out);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_CHECK_H_
