#include "common/io/payload_types.h"

#include <google/protobuf/descriptor.h>

#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/calibration.pb.h"
#include "tiltcal/proto/decode_params.pb.h"
#include "tiltcal/proto/gravity.pb.h"
#include "tiltcal/proto/gravity_params.pb.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/ground_params.pb.h"
#include "tiltcal/proto/imu.pb.h"
#include "tiltcal/proto/rig.pb.h"
#include "tiltcal/proto/scan.pb.h"
#include "tiltcal/proto/simulate_params.pb.h"
#include "tiltcal/proto/truth.pb.h"

namespace tiltcal {

const google::protobuf::Message* FindPayloadPrototype(const std::string& full_name) {
  // Referencing each type keeps its generated code in the link, so the
  // generated pool below knows it.
  static const google::protobuf::Message* const kAll[] = {
      &proto::ImuSample::default_instance(),       &proto::Scan::default_instance(),
      &proto::GroundPlane::default_instance(),     &proto::GravityReference::default_instance(),
      &proto::CalibrationResult::default_instance(), &proto::Rig::default_instance(),
      &proto::SimulationTruth::default_instance(), &proto::DecodeParams::default_instance(),
      &proto::GroundParams::default_instance(),    &proto::GravityParams::default_instance(),
      &proto::CalibrateParams::default_instance(), &proto::SimulateParams::default_instance(),
      &proto::InclinationSample::default_instance(),
  };
  for (const google::protobuf::Message* prototype : kAll) {
    if (prototype->GetDescriptor()->full_name() == full_name) return prototype;
  }
  return nullptr;
}

}  // namespace tiltcal
