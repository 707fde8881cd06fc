#include "stages/inspect/any_file.h"

#include <cstring>

#include "common/io/atomic_file.h"
#include "common/io/lz4_stream.h"
#include "common/io/payload_types.h"
#include "common/io/record_stream.h"
#include "common/io/text_proto.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/calibration.pb.h"
#include "tiltcal/proto/decode_params.pb.h"
#include "tiltcal/proto/gravity.pb.h"
#include "tiltcal/proto/gravity_params.pb.h"
#include "tiltcal/proto/ground_params.pb.h"
#include "tiltcal/proto/rig.pb.h"
#include "tiltcal/proto/simulate_params.pb.h"
#include "tiltcal/proto/truth.pb.h"

namespace tiltcal::inspect {

namespace {

bool StartsLikeStream(const std::string& head) {
  return head.compare(0, sizeof(kStreamMagic), kStreamMagic, sizeof(kStreamMagic)) == 0 ||
         (head.size() >= 4 && std::memcmp(head.data(), kLz4FrameMagic, 4) == 0);
}

// Text files carry no type name: the first schema that parses the whole file
// wins. Result types come first: their field names are the most specific.
Status ParseTextAsAnyType(const std::string& path, const std::string& text, AnyFile* file) {
  const google::protobuf::Message* const kTextTypes[] = {
      &proto::CalibrationResult::default_instance(), &proto::GravityReference::default_instance(),
      &proto::SimulationTruth::default_instance(),   &proto::Rig::default_instance(),
      &proto::DecodeParams::default_instance(),      &proto::GroundParams::default_instance(),
      &proto::GravityParams::default_instance(),     &proto::CalibrateParams::default_instance(),
      &proto::SimulateParams::default_instance(),
  };
  for (const google::protobuf::Message* prototype : kTextTypes) {
    std::unique_ptr<google::protobuf::Message> message(prototype->New());
    if (ParseTextProto(text, path, message.get()).ok()) {
      file->type = message->GetDescriptor();
      file->message = std::move(message);
      return Status::Ok();
    }
  }
  return Status::Error(path + ": neither a tiltcal record stream nor a text file of a known type");
}

}  // namespace

Status OpenAnyFile(const std::string& path, AnyFile* file) {
  file->path = path;
  std::string contents;
  TILTCAL_RETURN_IF_ERROR(ReadFileHead(path, 16, &contents));
  if (!StartsLikeStream(contents)) {
    TILTCAL_RETURN_IF_ERROR(ReadFileToString(path, &contents));
    if (contents.empty()) return Status::Error(path + ": empty file");
    return ParseTextAsAnyType(path, contents, file);
  }
  RecordReader reader;
  TILTCAL_RETURN_IF_ERROR(reader.Open(path));
  file->is_stream = true;
  file->header = reader.header();
  const google::protobuf::Message* prototype = FindPayloadPrototype(file->header.payload_type());
  if (prototype == nullptr) {
    return Status::Error(path + ": unknown payload type " + file->header.payload_type());
  }
  file->type = prototype->GetDescriptor();
  return Status::Ok();
}

Status ForEachRecord(const AnyFile& file,
                     const std::function<bool(int64_t, const google::protobuf::Message&)>& visit) {
  if (!file.is_stream) {
    visit(0, *file.message);
    return Status::Ok();
  }
  RecordReader reader;
  TILTCAL_RETURN_IF_ERROR(reader.Open(file.path));
  std::unique_ptr<google::protobuf::Message> record(
      FindPayloadPrototype(file.header.payload_type())->New());
  for (int64_t index = 0;; ++index) {
    bool end = false;
    TILTCAL_RETURN_IF_ERROR(reader.Read(record.get(), &end));
    if (end || !visit(index, *record)) return Status::Ok();
  }
}

}  // namespace tiltcal::inspect
