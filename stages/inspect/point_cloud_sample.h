#ifndef TILTCAL_STAGES_INSPECT_POINT_CLOUD_SAMPLE_H_
#define TILTCAL_STAGES_INSPECT_POINT_CLOUD_SAMPLE_H_

// A cheap look at sensor_msgs/PointCloud2 messages for the pre-flight check:
// which fields carry the per-point time and the ring, and every k-th point's
// coordinates and time offset. The per-point time conventions are those of
// tiltcal_decode (stages/decode/point_cloud_conversion.h):
//   `time_sec` + `time_nsec`  integers, absolute
//   `timestamp`               FLOAT64 absolute s (> 1e12: absolute ns)
//   `t`, `offset_time`        integers, ns relative to the header stamp
//   `time`                    FLOAT32/64 s relative to the header stamp
// Negative offsets mean the header stamp is at the end of the sweep.

#include <cstdint>
#include <string>
#include <vector>

#include "bag/ros1/messages.h"
#include "common/status.h"

namespace tiltcal::inspect {

struct CloudLayout {
  bool has_xyz = false;
  // The per-point time field ("" when none) and its type name ("FLOAT32"...).
  std::string time_field;
  std::string time_type;
  std::string time_meaning;  // "relative s", "relative ns", "absolute s", ...
  std::string ring_field;    // first of ring, line, laser_id ("" when none)
  std::string ring_type;
};
CloudLayout DescribeCloudLayout(const ros1::PointCloud2View& cloud);
// A Livox CustomMsg: x, y, z, the time `timebase + offset_time` (ns) and
// the ring `line`.
CloudLayout DescribeLivoxLayout();

// Every stride-th point of a cloud with finite coordinates (metres, LiDAR
// frame) and, when the cloud has a time field, finite time offsets from the
// header stamp (s).
struct CloudSample {
  std::vector<float> x, y, z;
  bool has_time = false;
  double min_time_offset_s = 0.0;
  double max_time_offset_s = 0.0;
};
// Errors name the layout problem (no x/y/z, a field outside the point, data
// shorter than its rows).
Status SampleCloud(const ros1::PointCloud2View& cloud, uint32_t stride, CloudSample* sample);
// The same for a Livox CustomMsg: time offsets timebase + offset_time − the
// header stamp.
void SampleLivox(const bag::LivoxCustomMessage& msg, uint32_t stride, CloudSample* sample);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_POINT_CLOUD_SAMPLE_H_
