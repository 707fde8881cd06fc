#include "stages/decode/message_sinks.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "common/io/record_stream.h"
#include "tiltcal/proto/imu.pb.h"

namespace tiltcal {

namespace {

// Where a message came from, for its errors.
std::string MessageContext(const std::string& bag, const ros1::MessageView& m, int64_t index) {
  return bag + ": topic '" + m.connection->topic + "' message " + std::to_string(index) +
         " (record time " + FormatSeconds(m.time_ns) + " s, chunk at byte " +
         std::to_string(m.chunk_pos) + ")";
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

Status ImuSink::Add(const ros1::MessageView& m, DecodeSummary* s) {
  const int64_t index = s->imu_messages++;
  Status status = ros1::DecodeImu(m.data, m.size, &message_);
  if (!status.ok()) {
    return status.WithContext(MessageContext(bag_, m, index) + ": sensor_msgs/Imu");
  }
  Record r;
  r.stamp_ns = ros1::RosTimeToNs(message_.header.stamp);
  r.record_ns = m.time_ns;
  for (int i = 0; i < 3; ++i) {
    r.angular_velocity[i] = message_.angular_velocity[i];
    r.linear_acceleration[i] = message_.linear_acceleration[i];
    if (!std::isfinite(r.angular_velocity[i]) || !std::isfinite(r.linear_acceleration[i])) {
      return Status::Error(MessageContext(bag_, m, index) +
                           ": sensor_msgs/Imu has a NaN or Inf angular velocity or linear "
                           "acceleration");
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

void ImuSink::ToSample(const Record& r, proto::ImuSample* sample) {
  sample->set_stamp_ns(r.stamp_ns);
  sample->set_record_stamp_ns(r.record_ns);
  auto* w = sample->mutable_angular_velocity_radps();
  w->set_x(r.angular_velocity[0]);
  w->set_y(r.angular_velocity[1]);
  w->set_z(r.angular_velocity[2]);
  auto* a = sample->mutable_linear_acceleration_mps2();
  a->set_x(r.linear_acceleration[0]);
  a->set_y(r.linear_acceleration[1]);
  a->set_z(r.linear_acceleration[2]);
}

Status ImuSink::Write(const std::string& path, const proto::Provenance& provenance,
                      DecodeSummary* s) {
  std::stable_sort(samples_.begin(), samples_.end(),
                   [](const Record& a, const Record& b) { return a.stamp_ns < b.stamp_ns; });
  RecordWriter writer;
  TILTCAL_RETURN_IF_ERROR(writer.Open(path, proto::ImuSample::descriptor()->full_name(),
                                      provenance, /*compress=*/false));
  proto::ImuSample sample;
  size_t first_of_stamp = 0;
  for (size_t i = 0; i < samples_.size(); ++i) {
    const Record& r = samples_[i];
    if (i > 0 && r.stamp_ns == samples_[i - 1].stamp_ns) {
      // Compared with the kept sample of this stamp.
      ++(SameValues(r, samples_[first_of_stamp]) ? s->imu_duplicates_dropped
                                                 : s->imu_conflicting_dropped);
      continue;
    }
    first_of_stamp = i;
    ToSample(r, &sample);
    TILTCAL_RETURN_IF_ERROR(writer.Write(sample));
    if (s->imu_written == 0) s->imu_first_stamp_ns = r.stamp_ns;
    s->imu_last_stamp_ns = r.stamp_ns;
    ++s->imu_written;
  }
  return writer.Close();
}

ScanSink::ScanSink(const std::string& bag, const proto::DecodeParams& params,
                   AsyncRecordWriter* writer)
    : bag_(bag), params_(params), writer_(writer) {
  conversion_.min_range_m = params.min_range_m();
}

Status ScanSink::Add(const ros1::MessageView& m, DecodeSummary* s) {
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

Status ScanSink::Convert(const ros1::MessageView& m, int64_t index, proto::Scan* scan,
                         bool* keep, DecodeSummary* s) {
  *keep = false;
  Status status = ros1::DecodePointCloud2(m.data, m.size, &cloud_);
  if (status.ok()) status = ConvertPointCloud2ToScan(cloud_, conversion_, scan);
  if (!status.ok()) {
    return status.WithContext(MessageContext(bag_, m, index) + ": sensor_msgs/PointCloud2");
  }
  s->points_dropped_invalid += scan->num_dropped_invalid();
  s->points_dropped_range += scan->num_dropped_zero_range();
  if (scan->time_source() == proto::POINT_TIME_NONE) {
    if (params_.require_point_time()) {
      return Status::Error(MessageContext(bag_, m, index) +
                           ": sensor_msgs/PointCloud2 has no per-point time field (fields: " +
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
  last_stamp_ns_ = scan->stamp_ns();
  scan->set_index(static_cast<uint32_t>(s->scans_written));
  scan->set_record_stamp_ns(m.time_ns);
  if (s->scans_written == 0) s->scan_first_stamp_ns = scan->stamp_ns();
  s->scan_last_stamp_ns = scan->stamp_ns();
  ++s->scans_written;
  s->points_written += scan->x_size();
  *keep = true;
  return Status::Ok();
}

}  // namespace tiltcal
