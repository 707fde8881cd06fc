#ifndef TILTCAL_COMMON_IO_TEXT_PROTO_H_
#define TILTCAL_COMMON_IO_TEXT_PROTO_H_

#include <string>

#include <google/protobuf/message.h>

#include "common/status.h"

namespace tiltcal {

// Parses a protobuf text-format file. Unknown fields, and a non-repeated
// field given twice in one message (also when its first value is the
// default), are errors; the message names the file, line and column and,
// for a duplicate, the field by its dotted path. A directory, another non-regular file or an
// empty file is an error, not an empty message.
Status ReadTextProto(const std::string& path, google::protobuf::Message* message);

// Parses text format from memory; `source_name` is used in error messages.
Status ParseTextProto(const std::string& text, const std::string& source_name,
                      google::protobuf::Message* message);

// Writes `message` in text format, atomically. Doubles round-trip exactly.
Status WriteTextProto(const std::string& path, const google::protobuf::Message& message);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_TEXT_PROTO_H_
