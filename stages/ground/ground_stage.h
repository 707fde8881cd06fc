#ifndef TILTCAL_STAGES_GROUND_GROUND_STAGE_H_
#define TILTCAL_STAGES_GROUND_GROUND_STAGE_H_

#include <ostream>
#include <string>

#include "common/status.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/ground_params.pb.h"

namespace tiltcal::ground {

// Paths of one tiltcal_ground run (the flags of the same names).
struct GroundPaths {
  std::string imu;         // imu.binpb (ImuSample stream)
  std::string scans;       // scans.binpb[.lz4] (Scan stream)
  std::string rig;         // rig.txtpb
  std::string params;      // the params file (provenance only; empty: the defaults)
  std::string out_ground;  // ground.binpb (GroundPlane stream)
  std::string out_scans;   // optional deskewed scans (LZ4-framed Scan stream)
  std::string command_line;
};

// Reads the IMU, rig and scans, deskews every scan, segments its ground and
// fits one plane per scan; writes ground.binpb (and the deskewed scans when
// paths.out_scans is set) atomically with provenance. Bad input (corrupt
// streams, mismatched point columns, NaN or non-monotonic IMU stamps, a
// non-unit rig rotation) is an error naming the file and record; numerical
// trouble in a scan is a rejected plane, not an error. Counts, rejected scans
// by reason and the timings go to `log` (nullptr: silent).
Status Run(const GroundPaths& paths, const proto::GroundParams& params, std::ostream* log);

// "GROUND_HIGH_RMS" -> "high_rms".
std::string ReasonName(proto::GroundRejectReason reason);

}  // namespace tiltcal::ground

#endif  // TILTCAL_STAGES_GROUND_GROUND_STAGE_H_
