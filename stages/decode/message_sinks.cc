#include "stages/decode/message_sinks.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "bag/ros1/messages.h"
#include "bag/ros2/messages.h"
#include "common/checked_conversion.h"
#include "common/io/record_stream.h"
#include "stages/decode/livox_conversion.h"
#include "tiltcal/proto/imu.pb.h"

namespace tiltcal {

namespace {

// Where a message came from, for its errors.
std::string MessageContext(const std::string& bag, const bag::Message& m, int64_t index) {
  return bag + ": topic '" + *m.topic + "' message " + std::to_string(index) +
         " (record time " + FormatSeconds(m.time_ns) + " s, " + bag::DescribePosition(m) + ")";
}

Status DecodeLivoxCustomMsg(const bag::Message& m, bag::LivoxCustomMessage* msg) {
  return m.encoding == bag::Encoding::kCdr ? ros2::DecodeLivoxCustomMsg(m.data, m.size, msg)
                                           : ros1::DecodeLivoxCustomMsg(m.data, m.size, msg);
}

// The message's type name in its own format, for errors.
const char* ImuTypeName(const bag::Message& m) {
  return m.encoding == bag::Encoding::kCdr ? ros2::kImuType : ros1::kImuType;
}
const char* PointCloud2TypeName(const bag::Message& m) {
  return m.encoding == bag::Encoding::kCdr ? ros2::kPointCloud2Type : ros1::kPointCloud2Type;
}

Status DecodeImu(const bag::Message& m, bag::ImuMessage* imu) {
  return m.encoding == bag::Encoding::kCdr ? ros2::DecodeImu(m.data, m.size, imu)
                                           : ros1::DecodeImu(m.data, m.size, imu);
}

Status DecodePointCloud2(const bag::Message& m, bag::PointCloud2View* cloud) {
  return m.encoding == bag::Encoding::kCdr ? ros2::DecodePointCloud2(m.data, m.size, cloud)
                                           : ros1::DecodePointCloud2(m.data, m.size, cloud);
}

// The median of `values` (the upper one of an even count); 0 when empty.
int64_t Median(std::vector<int64_t> values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + static_cast<long>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

std::string FormatSeconds(int64_t ns) {
  const bool negative = ns < 0;
  const uint64_t abs_ns = negative ? 0 - static_cast<uint64_t>(ns) : static_cast<uint64_t>(ns);
  return fmt::format("{}{}.{:09}", negative ? "-" : "", abs_ns / 1000000000, abs_ns % 1000000000);
}

ImuSink::ImuSink(const std::string& bag, int64_t expected_messages) : bag_(bag) {
  samples_.reserve(static_cast<size_t>(std::max<int64_t>(expected_messages, 0)));
}

Status ImuSink::Add(const bag::Message& m, DecodeSummary* s) {
  const int64_t index = s->imu_messages++;
  Status status = DecodeImu(m, &message_);
  if (!status.ok()) {
    return status.WithContext(MessageContext(bag_, m, index) + ": " + ImuTypeName(m));
  }
  Record r;
  r.stamp_ns = bag::RosTimeToNs(message_.header.stamp);
  r.record_ns = m.time_ns;
  if (r.stamp_ns == 0) {
    return Status::Error(MessageContext(bag_, m, index) +
                         ": sensor_msgs/Imu header stamp is 0 (never set by its driver)");
  }
  for (int i = 0; i < 3; ++i) {
    r.angular_velocity[i] = message_.angular_velocity[i];
    r.linear_acceleration[i] = message_.linear_acceleration[i];
    if (!std::isfinite(r.angular_velocity[i]) || !std::isfinite(r.linear_acceleration[i])) {
      return Status::Error(MessageContext(bag_, m, index) + ": " + ImuTypeName(m) +
                           " has a NaN or Inf angular velocity or linear acceleration");
    }
  }
  samples_.push_back(r);
  return Status::Ok();
}

bool ImuSink::SameValues(const Record& a, const Record& b) {
  for (int i = 0; i < 3; ++i) {
    if (a.angular_velocity[i] != b.angular_velocity[i] ||
        a.linear_acceleration[i] != b.linear_acceleration[i]) {
      return false;
    }
  }
  return true;
}

void ImuSink::ToSample(const Record& r, double accel_to_si, double gyro_to_si,
                       proto::ImuSample* sample) {
  sample->set_stamp_ns(r.stamp_ns);
  sample->set_record_stamp_ns(r.record_ns);
  auto* w = sample->mutable_angular_velocity_radps();
  w->set_x(r.angular_velocity[0] * gyro_to_si);
  w->set_y(r.angular_velocity[1] * gyro_to_si);
  w->set_z(r.angular_velocity[2] * gyro_to_si);
  auto* a = sample->mutable_linear_acceleration_mps2();
  a->set_x(r.linear_acceleration[0] * accel_to_si);
  a->set_y(r.linear_acceleration[1] * accel_to_si);
  a->set_z(r.linear_acceleration[2] * accel_to_si);
}

void ImuSink::SortAndDropRepeatedStamps(DecodeSummary* s) {
  std::stable_sort(samples_.begin(), samples_.end(),
                   [](const Record& a, const Record& b) { return a.stamp_ns < b.stamp_ns; });
  size_t kept = 0;  // samples_[0, kept) are the first samples of their stamps
  for (size_t i = 0; i < samples_.size(); ++i) {
    if (kept > 0 && samples_[i].stamp_ns == samples_[kept - 1].stamp_ns) {
      ++(SameValues(samples_[i], samples_[kept - 1]) ? s->imu_duplicates_dropped
                                                     : s->imu_conflicting_dropped);
      continue;
    }
    samples_[kept++] = samples_[i];
  }
  samples_.resize(kept);
  if (!samples_.empty()) {
    s->imu_first_stamp_ns = samples_.front().stamp_ns;
    s->imu_last_stamp_ns = samples_.back().stamp_ns;
  }
}

std::vector<imu::ImuReading> ImuSink::Readings() const {
  std::vector<imu::ImuReading> readings(samples_.size());
  for (size_t i = 0; i < samples_.size(); ++i) {
    const Record& r = samples_[i];
    readings[i].time_s = static_cast<double>(r.stamp_ns - samples_.front().stamp_ns) * 1e-9;
    readings[i].angular_velocity_radps = Eigen::Map<const Eigen::Vector3d>(r.angular_velocity);
    readings[i].linear_acceleration_mps2 = Eigen::Map<const Eigen::Vector3d>(r.linear_acceleration);
  }
  return readings;
}

decode::StampSpan ImuSink::Span() const {
  decode::StampSpan span;
  if (samples_.empty()) return span;
  std::vector<int64_t> delays_ns;
  delays_ns.reserve(samples_.size());
  for (const Record& r : samples_) delays_ns.push_back(r.record_ns - r.stamp_ns);
  span.first_ns = samples_.front().stamp_ns;
  span.last_ns = samples_.back().stamp_ns;
  span.median_record_delay_ns = Median(std::move(delays_ns));
  return span;
}

timing::ClockRate ImuSink::ClockRate(double window_s) const {
  std::vector<int64_t> stamps, records;
  stamps.reserve(samples_.size());
  records.reserve(samples_.size());
  for (const Record& r : samples_) {
    stamps.push_back(r.stamp_ns);
    records.push_back(r.record_ns);
  }
  return timing::EstimateClockRate(stamps, records, window_s);
}

timing::ClockRate ScanSink::ClockRate(double window_s) const {
  return timing::EstimateClockRate(stamps_ns_, records_ns_, window_s);
}

Status ImuSink::CheckStampGaps(double max_gap_s) const {
  for (size_t i = 1; i < samples_.size(); ++i) {
    const double gap_s = DifferenceSeconds(samples_[i].stamp_ns, samples_[i - 1].stamp_ns);
    if (gap_s > max_gap_s) {
      return Status::Error(fmt::format(
          "{}: IMU stamps jump by {:.3f} s from {} s to {} s (sample {} in stamp order, record "
          "time {} s), more than max_stamp_gap_s = {} s",
          bag_, gap_s, FormatSeconds(samples_[i - 1].stamp_ns), FormatSeconds(samples_[i].stamp_ns),
          i, FormatSeconds(samples_[i].record_ns), max_gap_s));
    }
  }
  return Status::Ok();
}

Status ImuSink::CheckPhysicalRange(const proto::ImuRangeParams& range, double accel_to_si,
                                   double gyro_to_si) const {
  for (size_t i = 0; i < samples_.size(); ++i) {
    const Record& r = samples_[i];
    const double accel_mps2 =
        Eigen::Map<const Eigen::Vector3d>(r.linear_acceleration).stableNorm() * accel_to_si;
    const double gyro_radps =
        Eigen::Map<const Eigen::Vector3d>(r.angular_velocity).stableNorm() * gyro_to_si;
    const bool accel_out = !(accel_mps2 <= range.max_linear_acceleration_mps2());
    if (accel_out || !(gyro_radps <= range.max_angular_velocity_radps())) {
      return Status::Error(fmt::format(
          "{}: IMU sample {} in stamp order (stamp {} s, record time {} s) reads {} {:.6g} {}, "
          "beyond any vehicle IMU's range (imu_range.{} = {}): a corrupt record",
          bag_, i, FormatSeconds(r.stamp_ns), FormatSeconds(r.record_ns),
          accel_out ? "|linear acceleration|" : "|angular velocity|",
          accel_out ? accel_mps2 : gyro_radps, accel_out ? "m/s²" : "rad/s",
          accel_out ? "max_linear_acceleration_mps2" : "max_angular_velocity_radps",
          accel_out ? range.max_linear_acceleration_mps2() : range.max_angular_velocity_radps()));
    }
  }
  return Status::Ok();
}

Status ImuSink::Write(const std::string& path, const proto::Provenance& provenance,
                      double accel_to_si, double gyro_to_si, RecordWriter* writer,
                      DecodeSummary* s) {
  TILTCAL_RETURN_IF_ERROR(writer->Open(path, proto::ImuSample::descriptor()->full_name(),
                                       provenance, /*compress=*/false));
  proto::ImuSample sample;
  for (const Record& r : samples_) {
    ToSample(r, accel_to_si, gyro_to_si, &sample);
    TILTCAL_RETURN_IF_ERROR(writer->Write(sample));
  }
  TILTCAL_RETURN_IF_ERROR(writer->Finish());
  s->imu_written = static_cast<int64_t>(samples_.size());
  return Status::Ok();
}

ScanSink::ScanSink(const std::string& bag, const proto::DecodeParams& params,
                   const std::string& lidar_type, AsyncRecordWriter* writer)
    : bag_(bag),
      params_(params),
      lidar_type_(lidar_type),
      livox_(IsLivoxCustomMsgType(lidar_type)),
      writer_(writer),
      stamp_shift_ns_(std::llround(params.lidar_stamp_shift_s() * 1e9)) {
  conversion_.min_range_m = params.min_range_m();
}

decode::StampSpan ScanSink::Span(const DecodeSummary& s) const {
  decode::StampSpan span;
  span.first_ns = s.scan_first_stamp_ns;
  span.last_ns = s.scan_last_stamp_ns;
  span.median_record_delay_ns = Median(record_delays_ns_);
  return span;
}

Status ScanSink::Add(const bag::Message& m, DecodeSummary* s) {
  const int64_t index = s->scan_messages++;
  auto* scan = static_cast<proto::Scan*>(writer_->Acquire());
  bool keep = false;
  Status status = Convert(m, index, scan, &keep, s);
  if (!status.ok() || !keep) {
    writer_->Release(scan);
    return status;
  }
  return writer_->Submit(scan);
}

Status ScanSink::DecodeAndConvert(const bag::Message& m, proto::Scan* scan) {
  if (livox_) {
    TILTCAL_RETURN_IF_ERROR(DecodeLivoxCustomMsg(m, &livox_message_));
    return ConvertLivoxCustomMsgToScan(livox_message_, params_.livox(), params_.min_range_m(),
                                       scan);
  }
  TILTCAL_RETURN_IF_ERROR(DecodePointCloud2(m, &cloud_));
  return ConvertPointCloud2ToScan(cloud_, conversion_, scan);
}

Status ScanSink::Convert(const bag::Message& m, int64_t index, proto::Scan* scan,
                         bool* keep, DecodeSummary* s) {
  *keep = false;
  const std::string type_name = livox_ ? lidar_type_ : PointCloud2TypeName(m);
  Status status = DecodeAndConvert(m, scan);
  if (!status.ok()) return status.WithContext(MessageContext(bag_, m, index) + ": " + type_name);
  if (scan->stamp_ns() == 0) {
    return Status::Error(MessageContext(bag_, m, index) + ": " + type_name +
                         " header stamp is 0 (never set by its driver)");
  }
  scan->set_stamp_ns(scan->stamp_ns() + stamp_shift_ns_);
  s->points_dropped_invalid += scan->num_dropped_invalid();
  s->points_dropped_range += scan->num_dropped_zero_range();
  s->points_dropped_noise_tag += scan->num_dropped_noise_tag();
  if (scan->time_source() == proto::POINT_TIME_NONE) {
    if (params_.require_point_time()) {
      return Status::Error(MessageContext(bag_, m, index) + ": " + PointCloud2TypeName(m) +
                           " has no per-point time field (fields: " +
                           DescribeFields(cloud_) + ") and require_point_time is set");
    }
    ++s->scans_without_point_time;
  }
  if (scan->x_size() == 0) {
    ++s->scans_empty_dropped;
    return Status::Ok();
  }
  if (scan->stamp_ns() <= last_stamp_ns_) {
    if (!params_.drop_non_monotonic()) {
      return Status::Error(MessageContext(bag_, m, index) + ": scan stamp " +
                           FormatSeconds(scan->stamp_ns()) +
                           " s is not after the previous scan's " +
                           FormatSeconds(last_stamp_ns_) +
                           " s (set drop_non_monotonic to drop such scans)");
    }
    ++s->scans_non_monotonic_dropped;
    return Status::Ok();
  }
  if (s->scans_written > 0 &&
      DifferenceSeconds(scan->stamp_ns(), last_stamp_ns_) > params_.max_stamp_gap_s()) {
    return Status::Error(fmt::format(
        "{}: scan stamp {} s is {:.3f} s after the previous scan's {} s, more than "
        "max_stamp_gap_s = {} s",
        MessageContext(bag_, m, index), FormatSeconds(scan->stamp_ns()),
        DifferenceSeconds(scan->stamp_ns(), last_stamp_ns_), FormatSeconds(last_stamp_ns_),
        params_.max_stamp_gap_s()));
  }
  last_stamp_ns_ = scan->stamp_ns();
  scan->set_index(static_cast<uint32_t>(s->scans_written));
  scan->set_record_stamp_ns(m.time_ns);
  record_delays_ns_.push_back(m.time_ns - scan->stamp_ns());
  stamps_ns_.push_back(scan->stamp_ns());
  records_ns_.push_back(m.time_ns);
  if (s->scans_written == 0) s->scan_first_stamp_ns = scan->stamp_ns();
  s->scan_last_stamp_ns = scan->stamp_ns();
  ++s->scans_written;
  s->points_written += scan->x_size();
  *keep = true;
  return Status::Ok();
}

}  // namespace tiltcal
