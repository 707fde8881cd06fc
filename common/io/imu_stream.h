#ifndef TILTCAL_COMMON_IO_IMU_STREAM_H_
#define TILTCAL_COMMON_IO_IMU_STREAM_H_

#include <cstdint>
#include <string>
#include <vector>

#include "common/imu/imu_reading.h"
#include "common/status.h"

namespace tiltcal {

// Reads an imu.binpb stream (tiltcal_decode) as readings with times in
// seconds relative to the first sample's stamp, which is returned in
// *first_stamp_ns. The readings are validated (finite, strictly increasing).
Status ReadImuReadings(const std::string& path, std::vector<imu::ImuReading>* readings,
                       int64_t* first_stamp_ns);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_IMU_STREAM_H_
