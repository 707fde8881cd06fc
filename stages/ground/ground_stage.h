#ifndef TILTCAL_STAGES_GROUND_GROUND_STAGE_H_
#define TILTCAL_STAGES_GROUND_GROUND_STAGE_H_

#include <map>
#include <ostream>
#include <string>

#include "common/status.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/ground_params.pb.h"

namespace tiltcal::ground {

// Paths of one tiltcal_ground run (flags of DESIGN §8).
struct GroundPaths {
  std::string imu;         // imu.binpb (ImuSample stream)
  std::string scans;       // scans.binpb[.lz4] (Scan stream)
  std::string rig;         // rig.txtpb
  std::string out_ground;  // ground.binpb (GroundPlane stream)
  std::string out_scans;   // optional deskewed scans (LZ4-framed Scan stream)
  std::string command_line;
};

// Counts and timings of a run.
struct GroundRunSummary {
  int num_scans = 0;
  int num_valid = 0;
  int num_deskewed = 0;
  std::map<proto::GroundRejectReason, int> rejected;  // by reason
  bool static_start = false;
  double static_duration_s = 0.0;
  double deskew_s = 0.0, segment_s = 0.0, fit_s = 0.0, total_s = 0.0;
};

// Reads the IMU, rig and scans, deskews every scan, segments its ground and
// fits one plane per scan; writes ground.binpb (and the deskewed scans when
// paths.out_scans is set) atomically with provenance. Bad input (corrupt
// streams, mismatched point columns, NaN or non-monotonic IMU stamps, a
// non-unit rig rotation) is an error naming the file and record; numerical
// trouble in a scan is a rejected plane, not an error. A summary of rejected
// scans by reason and the timings go to `log` (may be null).
Status Run(const GroundPaths& paths, const proto::GroundParams& params,
           GroundRunSummary* summary, std::ostream* log);

// "GROUND_HIGH_RMS" -> "high_rms".
std::string ReasonName(proto::GroundRejectReason reason);

}  // namespace tiltcal::ground

#endif  // TILTCAL_STAGES_GROUND_GROUND_STAGE_H_
