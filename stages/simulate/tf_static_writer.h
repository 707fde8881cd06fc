#ifndef TILTCAL_STAGES_SIMULATE_TF_STATIC_WRITER_H_
#define TILTCAL_STAGES_SIMULATE_TF_STATIC_WRITER_H_

// The simulated vehicle's URDF on /tf_static (proto SimTfStaticParams):
// base frame -> IMU frame, base frame -> LiDAR frame, in one
// tf2_msgs/TFMessage.

#include <cstdint>

#include "bag/ros1/bag_writer.h"
#include "bag/sensor_messages.h"
#include "common/status.h"
#include "stages/simulate/scenario.h"
#include "tiltcal/proto/simulate_params.pb.h"

namespace tiltcal::simulate {

// The frame ids must differ: base, IMU and LiDAR frame. The message names
// the field.
Status TfStaticParamsAreValid(const proto::SimulateParams& params);

// The two transforms, stamped `stamp_ns` (SimTfStaticParams: the true
// mounting, the LiDAR's with its error).
bag::TfMessage MakeTfStaticMessage(const proto::SimulateParams& params, int64_t stamp_ns);

// Writes the message on /tf_static when params.tf_static().write, before
// any other message: record time and stamp are the bag's earliest stamp
// (the first IMU sample, or a LiDAR stamp τ earlier). Nothing otherwise.
Status WriteTfStatic(const proto::SimulateParams& params, const Scenario& scenario,
                     ros1::BagWriter* writer);

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_TF_STATIC_WRITER_H_
