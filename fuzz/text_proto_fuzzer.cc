// libFuzzer harness: any bytes as a text-format params or rig file: parsed
// as CalibrateParams (the largest params message) and DecodeParams and
// checked against their schema bounds (common/io/params.h), and parsed and
// validated as a Rig (common/io/rig.h).
#include <cstddef>
#include <cstdint>
#include <string>

#include "common/io/params.h"
#include "common/io/rig.h"
#include "common/io/text_proto.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/decode_params.pb.h"
#include "tiltcal/proto/rig.pb.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  tiltcal::proto::CalibrateParams calibrate;
  if (tiltcal::ParseTextProto(text, "params", &calibrate).ok()) {
    (void)tiltcal::ValidateAgainstSchema(calibrate);
  }
  tiltcal::proto::DecodeParams decode;
  if (tiltcal::ParseTextProto(text, "params", &decode).ok()) {
    (void)tiltcal::ValidateAgainstSchema(decode);
  }
  tiltcal::proto::Rig rig;
  if (tiltcal::ParseTextProto(text, "rig", &rig).ok()) (void)tiltcal::ValidateRig(&rig);
  return 0;
}
