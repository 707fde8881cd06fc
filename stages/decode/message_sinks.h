#ifndef TILTCAL_STAGES_DECODE_MESSAGE_SINKS_H_
#define TILTCAL_STAGES_DECODE_MESSAGE_SINKS_H_

// Where the decode stage puts the messages of its two topics, one message at
// a time in record-time order, decoded from the ROS 1 wire format or CDR as
// the message says (bag::Message::encoding): the IMU sink keeps the samples to sort them
// by stamp at the end, the scan sink converts each cloud and hands it to the
// writer thread. Both count what they keep and drop in the DecodeSummary.

#include <cstdint>
#include <string>
#include <vector>

#include "bag/message_reader.h"
#include "bag/sensor_messages.h"
#include "common/imu/imu_reading.h"
#include "common/status.h"
#include "common/timing/clock_rate.h"
#include "stages/decode/async_record_writer.h"
#include "stages/decode/clock_domains.h"
#include "stages/decode/decode.h"
#include "stages/decode/point_cloud_conversion.h"
#include "tiltcal/proto/decode_params.pb.h"
#include "tiltcal/proto/imu.pb.h"
#include "tiltcal/proto/scan.pb.h"
#include "tiltcal/proto/stream.pb.h"

namespace tiltcal {

// ns -> "sec.nnnnnnnnn" exactly (no rounding through a double).
std::string FormatSeconds(int64_t ns);

// The sensor_msgs/Imu messages: kept in memory, then sorted by stamp,
// cleared of repeated stamps, converted to SI and written.
class ImuSink {
 public:
  ImuSink(const std::string& bag, int64_t expected_messages);

  // Decodes one message and keeps its sample. A NaN or Inf value is an error.
  Status Add(const bag::Message& m, DecodeSummary* s);

  bool empty() const { return samples_.empty(); }

  // Sorts by stamp (stable: record order among equal stamps) and drops
  // repeated stamps (the first sample of a stamp is kept), counting them.
  void SortAndDropRepeatedStamps(DecodeSummary* s);

  // After SortAndDropRepeatedStamps: the samples as published (time_s from
  // the first stamp) and their stamp span.
  std::vector<imu::ImuReading> Readings() const;
  decode::StampSpan Span() const;
  // The stamps' clock rate against the record times (common/timing).
  timing::ClockRate ClockRate(double window_s) const;

  // After SortAndDropRepeatedStamps: an error naming the sample when two
  // consecutive stamps are more than max_gap_s apart.
  Status CheckStampGaps(double max_gap_s) const;

  // After SortAndDropRepeatedStamps, with the units resolved: an error naming
  // the first sample whose |specific force| * accel_to_si or |angular
  // velocity| * gyro_to_si exceeds the range (a corrupt record: no IMU on a
  // vehicle reports it).
  Status CheckPhysicalRange(const proto::ImuRangeParams& range, double accel_to_si,
                            double gyro_to_si) const;

  // After SortAndDropRepeatedStamps: writes the stream with the specific
  // force multiplied by accel_to_si and the angular velocity by gyro_to_si
  // through *writer, finished under its temporary name (not committed).
  Status Write(const std::string& path, const proto::Provenance& provenance, double accel_to_si,
               double gyro_to_si, RecordWriter* writer, DecodeSummary* s);

 private:
  // One IMU sample kept until the end.
  struct Record {
    int64_t stamp_ns;
    int64_t record_ns;
    double angular_velocity[3];
    double linear_acceleration[3];
  };
  static bool SameValues(const Record& a, const Record& b);
  static void ToSample(const Record& r, double accel_to_si, double gyro_to_si,
                       proto::ImuSample* sample);

  std::string bag_;
  std::vector<Record> samples_;
  bag::ImuMessage message_;
};

// The LiDAR messages (sensor_msgs/PointCloud2 or a Livox CustomMsg, as
// `lidar_type` says): each converted to a Scan, its stamp
// shifted by params.lidar_stamp_shift_s, and handed to the writer thread,
// unless it has no valid point or its stamp does not advance (an error
// unless params.drop_non_monotonic).
class ScanSink {
 public:
  ScanSink(const std::string& bag, const proto::DecodeParams& params,
           const std::string& lidar_type, AsyncRecordWriter* writer);

  Status Add(const bag::Message& m, DecodeSummary* s);

  // The (shifted) stamp span of the scans written so far.
  decode::StampSpan Span(const DecodeSummary& s) const;
  // The (shifted) stamps' clock rate against the record times.
  timing::ClockRate ClockRate(double window_s) const;

 private:
  // Decodes the message and converts it into *scan (its type's decoder).
  Status DecodeAndConvert(const bag::Message& m, proto::Scan* scan);
  // Converts the message into *scan; *keep says whether it is written.
  Status Convert(const bag::Message& m, int64_t index, proto::Scan* scan, bool* keep,
                 DecodeSummary* s);

  std::string bag_;
  const proto::DecodeParams& params_;
  std::string lidar_type_;
  bool livox_ = false;  // the topic holds Livox CustomMsg
  AsyncRecordWriter* writer_;
  PointConversionOptions conversion_;
  bag::PointCloud2View cloud_;
  bag::LivoxCustomMessage livox_message_;
  int64_t stamp_shift_ns_ = 0;
  int64_t last_stamp_ns_ = INT64_MIN;
  std::vector<int64_t> record_delays_ns_;  // record time − shifted stamp, per written scan
  std::vector<int64_t> stamps_ns_, records_ns_;  // per written scan
};

}  // namespace tiltcal

#endif  // TILTCAL_STAGES_DECODE_MESSAGE_SINKS_H_
