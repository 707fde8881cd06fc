#include "common/io/imu_stream.h"

#include "common/checked_conversion.h"
#include "common/io/eigen_proto.h"
#include "common/io/record_stream.h"
#include "tiltcal/proto/imu.pb.h"

namespace tiltcal {

Status ReadImuReadings(const std::string& path, std::vector<imu::ImuReading>* readings,
                       int64_t* first_stamp_ns) {
  RecordReader reader;
  TILTCAL_RETURN_IF_ERROR(reader.Open(path, proto::ImuSample::descriptor()->full_name()));
  readings->clear();
  proto::ImuSample sample;
  for (;;) {
    bool end = false;
    TILTCAL_RETURN_IF_ERROR(reader.Read(&sample, &end));
    if (end) break;
    if (readings->empty()) *first_stamp_ns = sample.stamp_ns();
    imu::ImuReading reading;
    reading.time_s = DifferenceSeconds(sample.stamp_ns(), *first_stamp_ns);
    reading.angular_velocity_radps = ToEigen(sample.angular_velocity_radps());
    reading.linear_acceleration_mps2 = ToEigen(sample.linear_acceleration_mps2());
    readings->push_back(reading);
  }
  return imu::ValidateImuReadings(*readings).WithContext(path);
}

}  // namespace tiltcal
