#ifndef TILTCAL_STAGES_INSPECT_PCD_EXPORT_H_
#define TILTCAL_STAGES_INSPECT_PCD_EXPORT_H_

#include <cstdint>
#include <ostream>
#include <string>

#include "common/status.h"

namespace tiltcal::inspect {

struct PcdOptions {
  int64_t record = 0;       // index of the scan in the stream
  std::string ground_path;  // optional ground.binpb with point masks
  std::string out_path;     // the PCD to write
};

// `tiltcal_inspect pcd SCANS --record=N [--ground=ground.binpb] --out=scan.pcd`:
// writes scan N (raw or deskewed) as a binary PCD (binary_pcd.h) with the fields
// x y z intensity (float32), ring (uint32), time_offset_ns (int32) and, with
// a ground file, label (uint8: 0 non-ground, 1 ground, 2 ground used by the
// plane fit) for pcl_viewer / CloudCompare. The ground record is the one with
// the same scan_index and stamp. The file is written atomically; a one-line
// summary goes to `log`.
Status RunPcd(const std::string& scans_path, const PcdOptions& options, std::ostream& log);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_PCD_EXPORT_H_
