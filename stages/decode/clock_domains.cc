#include "stages/decode/clock_domains.h"

#include <algorithm>
#include <cmath>
#include <ctime>

#include <fmt/format.h>

namespace tiltcal::decode {

namespace {

double Seconds(int64_t ns) { return static_cast<double>(ns) * 1e-9; }

// "2026-12-01 17:52:30 UTC" of a stamp in ns since the epoch.
std::string UtcText(int64_t ns) {
  const std::time_t seconds = static_cast<std::time_t>(std::floor(Seconds(ns)));
  std::tm utc{};
  if (gmtime_r(&seconds, &utc) == nullptr) return "?";
  char text[32];
  if (std::strftime(text, sizeof(text), "%Y-%m-%d %H:%M:%S UTC", &utc) == 0) return "?";
  return text;
}

std::string SpanText(const char* sensor, const StampSpan& span) {
  return fmt::format("{} stamps {:.3f} .. {:.3f} s ({} .. {})", sensor, Seconds(span.first_ns),
                     Seconds(span.last_ns), UtcText(span.first_ns), UtcText(span.last_ns));
}

StampSpan Shifted(const StampSpan& span, double shift_s) {
  const int64_t shift_ns = std::llround(shift_s * 1e9);
  return {span.first_ns + shift_ns, span.last_ns + shift_ns,
          span.median_record_delay_ns - shift_ns};
}

}  // namespace

double StampOverlapSeconds(const StampSpan& imu, const StampSpan& lidar) {
  return Seconds(std::min(imu.last_ns, lidar.last_ns) - std::max(imu.first_ns, lidar.first_ns));
}

double SuggestedLidarStampShiftSeconds(const StampSpan& imu, const StampSpan& lidar,
                                       double current_shift_s) {
  return current_shift_s + Seconds(lidar.median_record_delay_ns - imu.median_record_delay_ns);
}

Status CheckClockDomains(const std::string& bag, const StampSpan& imu, const StampSpan& lidar,
                         double lidar_stamp_shift_s) {
  const double overlap_s = StampOverlapSeconds(imu, lidar);
  if (overlap_s >= 0.0) return Status::Ok();
  const bool lidar_later = lidar.first_ns > imu.last_ns;
  const double from_records_s = SuggestedLidarStampShiftSeconds(imu, lidar, lidar_stamp_shift_s);
  const bool records_bring_together =
      StampOverlapSeconds(imu, Shifted(lidar, from_records_s - lidar_stamp_shift_s)) >= 0.0;
  const std::string suggestion =
      records_bring_together
          ? fmt::format("the bag's record times suggest lidar_stamp_shift_s: {:.3f}",
                        from_records_s)
          : fmt::format("lidar_stamp_shift_s: {:.3f} would align the first stamps",
                        lidar_stamp_shift_s + Seconds(imu.first_ns - lidar.first_ns));
  return Status::Error(fmt::format(
      "{}: the LiDAR and IMU stamps do not overlap (two clocks?): {}, {}{}, the LiDAR {:.3f} s "
      "{} the IMU; set lidar_stamp_shift_s in the decode params (added to every LiDAR stamp, "
      "s) to decode anyway: {}",
      bag, SpanText("IMU", imu), SpanText("LiDAR", lidar),
      lidar_stamp_shift_s != 0.0 ? fmt::format(" (after lidar_stamp_shift_s {:.3f})",
                                               lidar_stamp_shift_s)
                                 : "",
      -overlap_s, lidar_later ? "after" : "before", suggestion));
}

}  // namespace tiltcal::decode
