#ifndef TILTCAL_COMMON_IO_PAYLOAD_TYPES_H_
#define TILTCAL_COMMON_IO_PAYLOAD_TYPES_H_

#include <string>

#include <google/protobuf/message.h>

namespace tiltcal {

// The default instance of the message type named `full_name` (e.g.
// "tiltcal.proto.Scan"), or nullptr if it is not one of ours. Every proto
// type of the project is linked in, so generic tools can decode any file.
const google::protobuf::Message* FindPayloadPrototype(const std::string& full_name);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_PAYLOAD_TYPES_H_
