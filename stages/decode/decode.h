#ifndef TILTCAL_STAGES_DECODE_DECODE_H_
#define TILTCAL_STAGES_DECODE_DECODE_H_

// The decode stage: a ROS1 bag -> imu.binpb (tiltcal.proto.ImuSample records,
// always in m/s² and rad/s) and scans.binpb.lz4 (tiltcal.proto.Scan records,
// LZ4-framed), both with provenance, both strictly increasing in stamp_ns.

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "bag/input/static_transforms.h"
#include "common/status.h"
#include "common/timing/clock_rate.h"
#include "tiltcal/proto/decode_params.pb.h"

namespace tiltcal {

// Every path of one decode run.
struct DecodePaths {
  std::string bag;
  std::string rig;  // optional rig.txtpb: topics, IMU units, the up direction for the sign check
  std::string out_imu;
  std::string out_scans;
  std::string params;        // the params file ("" = the stage defaults), for the provenance
  std::string command_line;  // recorded in the provenance
};

// What a run did, for the summary and for tests.
struct DecodeSummary {
  std::string imu_topic;
  std::string lidar_topic;
  std::string lidar_type;  // sensor_msgs/PointCloud2 or a Livox CustomMsg type, as in the bag
  bool indexed = true;
  int64_t salvaged_messages = 0;
  std::string salvage_note;
  // What the bag reader left out, one line each (bag::MessageReader::warnings()).
  std::vector<std::string> bag_warnings;
  int64_t imu_messages = 0;         // read from the bag (inside the window)
  int64_t imu_written = 0;
  int64_t imu_duplicates_dropped = 0;   // same stamp and same values
  int64_t imu_conflicting_dropped = 0;  // same stamp, other values (first kept)
  int64_t scan_messages = 0;
  int64_t scans_written = 0;
  int64_t scans_non_monotonic_dropped = 0;
  int64_t scans_empty_dropped = 0;  // no valid point left
  int64_t scans_without_point_time = 0;
  int64_t points_written = 0;
  int64_t points_dropped_invalid = 0;
  int64_t points_dropped_range = 0;
  int64_t points_dropped_noise_tag = 0;  // Livox: tag flags noise (livox.noise_tag_mask)
  int64_t imu_first_stamp_ns = 0, imu_last_stamp_ns = 0;
  int64_t scan_first_stamp_ns = 0, scan_last_stamp_ns = 0;  // after lidar_stamp_shift_s
  double stamp_overlap_s = 0.0;  // time covered by both the IMU and the LiDAR stamps
  // The LiDAR clock's rate against the IMU's (DecodeParams.clock_drift), and
  // the sentence that reports it when the drift matters ("" otherwise).
  timing::RelativeClockRate lidar_clock_vs_imu;
  std::string clock_drift_note;
  double accel_to_si = 1.0;      // factors applied to the published IMU values
  double gyro_to_si = 1.0;
  std::vector<std::string> imu_notes;     // units and sign: what was decided and why
  std::vector<std::string> imu_warnings;  // the notes that need the user's attention
  uint64_t bag_bytes = 0;
  std::string bag_format;              // "ROS 1 bag", "2 files (ROS 1 bag, MCAP)", ...
  std::vector<std::string> bag_files;  // every file read, in file-name order
  int64_t duplicates_dropped = 0;      // the same message in two files, given once
  uint64_t chunks_decompressed = 0;
  // What /tf_static says about the extrinsic (also in both outputs'
  // provenance, Provenance.tf_static).
  bag::StaticTransforms tf_static;
  double wall_s = 0.0;
};

// Decodes the bag into the two streams and fills *summary. The IMU's units
// are resolved (decode/imu_units_resolution.h) and its values converted to
// SI; LiDAR stamps are shifted by params.lidar_stamp_shift_s and must overlap
// the IMU's (decode/clock_domains.h). `log` receives the progress (only when
// it is a terminal) and the final summary with the unit notes; nullptr =
// silent. Errors are one line naming the file and the record. Outputs
// appear only when the whole run succeeded.
Status Decode(const DecodePaths& paths, const proto::DecodeParams& params, std::ostream* log,
              DecodeSummary* summary);

// The stage: Decode without the summary.
Status Run(const DecodePaths& paths, const proto::DecodeParams& params, std::ostream* log);

}  // namespace tiltcal

#endif  // TILTCAL_STAGES_DECODE_DECODE_H_
