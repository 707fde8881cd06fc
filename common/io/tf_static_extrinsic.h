#ifndef TILTCAL_COMMON_IO_TF_STATIC_EXTRINSIC_H_
#define TILTCAL_COMMON_IO_TF_STATIC_EXTRINSIC_H_

// The IMU-from-LiDAR extrinsic that the bag's /tf_static gave, as
// tiltcal_decode recorded it in the provenance of its outputs
// (Provenance.tf_static, docs/design.md §4): for a stage that wants the
// vehicle's URDF extrinsic, e.g. as a starting value when the rig states
// none. The stream's records are not read.

#include <optional>
#include <string>

#include "common/io/eigen_proto.h"
#include "common/status.h"
#include "tiltcal/proto/stream.pb.h"

namespace tiltcal {

// Reads the header of the decode output `stream_path` (imu.binpb or
// scans.binpb.lz4). *imu_from_lidar is (C_bl, r_b^{lb}) when a chain of
// static transforms joined the IMU's and the LiDAR's frames, else nullopt
// (no /tf_static, no chain, or a stream decoded before decode recorded it).
// `record`, when given, receives the whole record (frames, chain, summary).
// Errors: a stream that cannot be opened or has no valid header, or a
// recorded extrinsic that is not a finite rigid transform.
Status ReadTfStaticExtrinsic(const std::string& stream_path,
                             std::optional<Rigid3d>* imu_from_lidar,
                             proto::TfStaticExtrinsic* record = nullptr);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_TF_STATIC_EXTRINSIC_H_
