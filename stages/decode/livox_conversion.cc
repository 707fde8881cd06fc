#include "stages/decode/livox_conversion.h"

#include <cmath>
#include <cstdint>
#include <limits>

#include <fmt/format.h>

#include "bag/ros1/messages.h"
#include "bag/ros2/messages.h"
#include "stages/decode/point_cloud_conversion.h"

namespace tiltcal {

bool IsLivoxCustomMsgType(const std::string& type) {
  return type == ros1::kLivoxCustomMsgType || type == ros1::kLivox2CustomMsgType ||
         type == ros2::kLivox2CustomMsgType || type == ros2::kLivoxInterfacesCustomMsgType;
}

Status ConvertLivoxCustomMsgToScan(const bag::LivoxCustomMessage& msg,
                                   const proto::LivoxParams& params, double min_range_m,
                                   proto::Scan* scan) {
  if (!IsValidUtf8(msg.header.frame_id)) {
    return Status::Error("header.frame_id is not valid UTF-8");
  }
  const int64_t stamp_ns = bag::RosTimeToNs(msg.header.stamp);
  if (msg.timebase > static_cast<uint64_t>(std::numeric_limits<int64_t>::max())) {
    return Status::Error(fmt::format("timebase {} ns is past the int64 ns range", msg.timebase));
  }
  // timebase − stamp, ns; both are below 2^63, so the difference fits int64.
  const int64_t base_from_stamp_ns = static_cast<int64_t>(msg.timebase) - stamp_ns;
  const double difference_s = static_cast<double>(base_from_stamp_ns) * 1e-9;
  if (std::fabs(difference_s) > params.max_timebase_stamp_difference_s()) {
    return Status::Error(fmt::format(
        "timebase {} ns is {:.6f} s from header.stamp {} ns, more than "
        "livox.max_timebase_stamp_difference_s = {} s (the point times and the scan stamp "
        "would be on different clocks)",
        msg.timebase, difference_s, stamp_ns, params.max_timebase_stamp_difference_s()));
  }
  scan->Clear();
  scan->set_stamp_ns(stamp_ns);
  scan->set_frame_id(msg.header.frame_id);
  scan->set_time_source(proto::POINT_TIME_LIVOX_CUSTOM_MSG);
  const int n = static_cast<int>(msg.points.size());
  for (auto* column : {scan->mutable_x(), scan->mutable_y(), scan->mutable_z(),
                       scan->mutable_intensity()}) {
    column->Reserve(n);
  }
  scan->mutable_ring()->Reserve(n);
  scan->mutable_time_offset_ns()->Reserve(n);
  const double min_range2 = min_range_m * min_range_m;
  const uint32_t noise_mask = params.noise_tag_mask();
  uint32_t invalid = 0, too_close = 0, noise = 0;
  for (const bag::LivoxPoint& p : msg.points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      ++invalid;
      continue;
    }
    const double range2 = static_cast<double>(p.x) * p.x + static_cast<double>(p.y) * p.y +
                          static_cast<double>(p.z) * p.z;
    if (range2 == 0.0 || range2 < min_range2) {
      ++too_close;
      continue;
    }
    if ((p.tag & noise_mask) != 0) {
      ++noise;
      continue;
    }
    const int64_t offset_ns = base_from_stamp_ns + static_cast<int64_t>(p.offset_time);
    if (offset_ns > std::numeric_limits<int32_t>::max() ||
        offset_ns < std::numeric_limits<int32_t>::min()) {
      return Status::Error(fmt::format(
          "point time timebase + offset_time ({} ns) is {} ns from header.stamp, outside the "
          "int32 ns range of a scan",
          p.offset_time, offset_ns));
    }
    scan->add_x(p.x);
    scan->add_y(p.y);
    scan->add_z(p.z);
    scan->add_intensity(static_cast<float>(p.reflectivity));
    scan->add_ring(p.line);
    scan->add_time_offset_ns(static_cast<int32_t>(offset_ns));
  }
  scan->set_num_dropped_invalid(invalid);
  scan->set_num_dropped_zero_range(too_close);
  scan->set_num_dropped_noise_tag(noise);
  return Status::Ok();
}

}  // namespace tiltcal
