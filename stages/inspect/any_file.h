#ifndef TILTCAL_STAGES_INSPECT_ANY_FILE_H_
#define TILTCAL_STAGES_INSPECT_ANY_FILE_H_

#include <functional>
#include <memory>
#include <string>

#include <google/protobuf/message.h>

#include "common/status.h"
#include "tiltcal/proto/stream.pb.h"

namespace tiltcal::inspect {

// Any file of the pipeline, opened without knowing its type: a record
// stream (plain or LZ4, type from its header) or a single text-format
// message (type found by parsing against our schemas).
struct AnyFile {
  std::string path;
  bool is_stream = false;
  proto::StreamHeader header;                          // streams only
  std::unique_ptr<google::protobuf::Message> message;  // text files only
  const google::protobuf::Descriptor* type = nullptr;  // record / message type
};

Status OpenAnyFile(const std::string& path, AnyFile* file);

// Calls `visit(index, record)` for each record of a stream, or once for a text
// file's message. Stops early when `visit` returns false.
Status ForEachRecord(const AnyFile& file,
                     const std::function<bool(int64_t, const google::protobuf::Message&)>& visit);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_ANY_FILE_H_
