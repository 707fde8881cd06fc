#ifndef TILTCAL_STAGES_INSPECT_RIG_DRAFT_H_
#define TILTCAL_STAGES_INSPECT_RIG_DRAFT_H_

// `tiltcal_inspect rig`: a first rig.txtpb drafted from a bag, for a user who
// has only the recording. It states the IMU and LiDAR topics (with their
// frame ids in comments), the IMU units the check detects, the
// IMU-from-LiDAR of the bag's /tf_static as imu_from_lidar (or, without one,
// a comment that the calibration will estimate it and a commented template
// for the starting value the rig requires), and imu_height_m as a commented
// line with how to measure it. The text parses as a Rig (proto rig.proto);
// tiltcal_decode accepts it once imu_height_m is filled in (and, without
// /tf_static, imu_from_lidar).

#include <ostream>
#include <string>

#include "common/status.h"
#include "stages/inspect/check_findings.h"
#include "tiltcal/proto/check_params.pb.h"

namespace tiltcal::inspect {

struct RigDraftPaths {
  std::string bag;  // required: any input tiltcal_decode reads
  std::string out;  // the rig to write (atomically); "" = standard output
};

// The draft's text from the check's findings (no I/O). Errors: no IMU or no
// LiDAR topic could be chosen (the findings' problems say why).
Status DraftRigText(const CheckFindings& findings, std::string* text);

// Surveys the bag as `check` does, drafts the rig and writes it to paths.out
// (or `out`); says on `log` what it wrote.
Status RunRigDraft(const RigDraftPaths& paths, const proto::CheckParams& params,
                   std::ostream& out, std::ostream& log);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_RIG_DRAFT_H_
