#ifndef TILTCAL_STAGES_DECODE_CLOCK_DOMAINS_H_
#define TILTCAL_STAGES_DECODE_CLOCK_DOMAINS_H_

// Whether the IMU's and the LiDAR's header stamps can be on one clock. A
// driver may stamp with the sensor's own clock (time since power-on, or a
// clock never set) while the other stamps with the host's ROS time: their
// stamps are then minutes or years apart. A time offset τ of any size is the
// calibration's to estimate when the stamps overlap at least in part; spans
// that do not overlap at all cannot be calibrated and need the user's shift.

#include <cstdint>
#include <string>

#include "common/status.h"

namespace tiltcal::decode {

// The header stamps of one sensor, ns since the epoch of its clock, and the
// median of (bag record time − header stamp), ns: how far the sensor's
// stamps run behind the recorder's clock (transport latency, or the offset
// between two clocks).
struct StampSpan {
  int64_t first_ns = 0;
  int64_t last_ns = 0;
  int64_t median_record_delay_ns = 0;
};

// Length of the time both spans cover, s; negative: the gap between them.
double StampOverlapSeconds(const StampSpan& imu, const StampSpan& lidar);

// The lidar_stamp_shift_s that would put the LiDAR stamps on the IMU's
// clock, from the record times: the LiDAR stamp t_l was recorded at about
// t_l + d_l and an IMU stamp t_i at about t_i + d_i (d = median record
// delay), so t_l on the IMU clock is about t_l + d_l − d_i. `lidar` holds
// the stamps already shifted by `current_shift_s`.
double SuggestedLidarStampShiftSeconds(const StampSpan& imu, const StampSpan& lidar,
                                       double current_shift_s);

// Error when the spans do not overlap at all: one line naming the bag, both
// spans (seconds since the epoch and UTC), the gap, the params field
// lidar_stamp_shift_s and a value for it (from the record times when they
// bring the spans together, else the one that aligns the first stamps).
Status CheckClockDomains(const std::string& bag, const StampSpan& imu, const StampSpan& lidar,
                         double lidar_stamp_shift_s);

}  // namespace tiltcal::decode

#endif  // TILTCAL_STAGES_DECODE_CLOCK_DOMAINS_H_
