#ifndef TILTCAL_STAGES_DECODE_LIVOX_CONVERSION_H_
#define TILTCAL_STAGES_DECODE_LIVOX_CONVERSION_H_

// Livox CustomMsg -> tiltcal.proto.Scan, the same columns as a PointCloud2:
//   stamp_ns        header.stamp (the Livox drivers set it to timebase)
//   x, y, z         the point, m, LiDAR frame
//   intensity       reflectivity (0..255)
//   ring            line (0-5 Avia, 0-3 Mid-360); a non-repetitive pattern,
//                   so no order of rings or azimuths is implied
//   time_offset_ns  timebase + offset_time − header.stamp, ns
//   time_source     POINT_TIME_LIVOX_CUSTOM_MSG
// Points are dropped and counted in this order: a NaN / Inf coordinate
// (num_dropped_invalid), zero range (no return: the drivers publish such
// points at the origin) or closer than min_range_m (num_dropped_zero_range),
// a tag with a bit of noise_tag_mask set (num_dropped_noise_tag).
// A timebase further than max_timebase_stamp_difference_s from header.stamp,
// or a point time whose offset from the stamp does not fit int32 ns, is an
// error (the caller adds file, topic and message).

#include <string>

#include "bag/sensor_messages.h"
#include "common/status.h"
#include "tiltcal/proto/decode_params.pb.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal {

// True for the Livox CustomMsg type names decode reads: livox_ros_driver/CustomMsg,
// livox_ros_driver2/CustomMsg (ROS 1), livox_ros_driver2/msg/CustomMsg,
// livox_interfaces/msg/CustomMsg (ROS 2).
bool IsLivoxCustomMsgType(const std::string& type);

// Fills stamp_ns, frame_id, the point columns, time_source and the dropped
// counts of `scan` (cleared first; index and record_stamp_ns are the caller's).
Status ConvertLivoxCustomMsgToScan(const bag::LivoxCustomMessage& msg,
                                   const proto::LivoxParams& params, double min_range_m,
                                   proto::Scan* scan);

}  // namespace tiltcal

#endif  // TILTCAL_STAGES_DECODE_LIVOX_CONVERSION_H_
