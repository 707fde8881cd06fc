#ifndef TILTCAL_STAGES_DECODE_POINT_CLOUD_CONVERSION_H_
#define TILTCAL_STAGES_DECODE_POINT_CLOUD_CONVERSION_H_

// sensor_msgs/PointCloud2 -> tiltcal.proto.Scan columns, driven only by the
// PointField list (never an assumed struct layout):
//   x, y, z         FLOAT32 or FLOAT64
//   intensity       first of `intensity`, `i`, `reflectivity` (any numeric
//                   type, converted to float); 0 when absent
//   ring            first of `ring`, `line`, `laser_id` (any numeric type);
//                   the column stays empty when absent
//   per-point time  (time_offset_ns = point time - header.stamp, int32 ns)
//     `time_sec` + `time_nsec` integers, absolute          POINT_TIME_SEC_NSEC
//     `timestamp` FLOAT64 absolute s (Hesai, RoboSense)   POINT_TIME_ABSOLUTE_SECONDS
//        (values > 1e12 are absolute ns, Livox driver 2)  POINT_TIME_ABSOLUTE_NS_DOUBLE
//     `t` integer ns relative to the stamp (Ouster)       POINT_TIME_OUSTER_T
//     `time` FLOAT32/64 s relative, may be < 0 (Velodyne) POINT_TIME_VELODYNE_TIME
//     `offset_time` integer ns relative (Livox)           POINT_TIME_OFFSET_TIME_NS
//     none: all offsets 0                                  POINT_TIME_NONE
// Rows may be padded (row_step > width * point_step), fields unaligned (every
// value is memcpy'd), big-endian clouds are byte-swapped. Points with a NaN /
// Inf coordinate or time are dropped and counted as invalid; points at zero
// range or closer than min_range_m are dropped and counted as zero range.

#include <string>

#include "bag/ros1/messages.h"
#include "common/status.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal {

struct PointConversionOptions {
  double min_range_m = 0.0;  // points with range below this are dropped, m
  // Little-endian clouds with FLOAT32 x/y/z, an absent / FLOAT32 / UINT8 /
  // UINT16 intensity, an absent / UINT8 / UINT16 ring and no time, a FLOAT32
  // `time` (Velodyne) or a UINT32 `t` (Ouster) go through a loop compiled for
  // exactly that layout; its output is byte-identical to the generic loop
  // (false forces the generic loop, for tests and comparisons).
  bool allow_fast_path = true;
};

// Fills stamp_ns, frame_id, the point columns, time_source and the dropped
// counts of `scan` (which is cleared first; index and record_stamp_ns are left
// to the caller). Errors describe the layout problem (missing x, a field
// outside the point, data shorter than the rows, a time offset outside int32).
Status ConvertPointCloud2ToScan(const ros1::PointCloud2View& cloud,
                                const PointConversionOptions& options, proto::Scan* scan);

// True when `text` is well-formed UTF-8 (no overlong forms, surrogates or
// code points above U+10FFFF), as a protobuf string field must be.
bool IsValidUtf8(const std::string& text);

// "x:FLOAT32@0 y:FLOAT32@4 ..." for messages.
std::string DescribeFields(const ros1::PointCloud2View& cloud);

}  // namespace tiltcal

#endif  // TILTCAL_STAGES_DECODE_POINT_CLOUD_CONVERSION_H_
