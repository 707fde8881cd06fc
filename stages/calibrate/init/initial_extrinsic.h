#ifndef TILTCAL_STAGES_CALIBRATE_INIT_INITIAL_EXTRINSIC_H_
#define TILTCAL_STAGES_CALIBRATE_INIT_INITIAL_EXTRINSIC_H_

// tiltcal_initial_extrinsic: the sequence's rig, i.e. the dataset's rig with
// the starting extrinsic every later stage uses (docs/design.md §9, "The
// starting extrinsic"):
//  - the guess: the rig's imu_from_lidar, else the bag's /tf_static (as
//    decode recorded it in imu.binpb), else none (rotation_search.start_from);
//  - its rotation corrected by any angle from the motion
//    (rotation_from_motion.h);
//  - the translation: the guess's, else zero and unknown (no prior in the
//    calibration).
// The output rig says where the start came from (Rig.starting_extrinsic).

#include <iosfwd>
#include <string>

#include "common/status.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/rig.pb.h"

namespace tiltcal::calibrate {

struct InitialExtrinsicPaths {
  std::string imu;    // imu.binpb
  std::string scans;  // scans.binpb.lz4
  std::string rig;    // the dataset's rig.txtpb (imu_from_lidar optional)
  std::string out;    // the sequence's rig.txtpb
};

// Reads the inputs and finds the starting extrinsic: the sequence's rig in
// *sequence_rig (its gravity_reference rewritten relative to paths.out's
// folder), nothing written; one progress line per step on *log (may be
// null). A motion that cannot decide is Status::NotDetermined.
Status FindSequenceRig(const InitialExtrinsicPaths& paths, const proto::CalibrateParams& params,
                       std::ostream* log, proto::Rig* sequence_rig);

// FindSequenceRig, then the sequence's rig written atomically to paths.out.
Status RunInitialExtrinsic(const InitialExtrinsicPaths& paths,
                           const proto::CalibrateParams& params, std::ostream* log,
                           proto::Rig* sequence_rig);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_INIT_INITIAL_EXTRINSIC_H_
