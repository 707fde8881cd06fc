#ifndef TILTCAL_COMMON_IO_PROVENANCE_H_
#define TILTCAL_COMMON_IO_PROVENANCE_H_

#include <string>
#include <utility>
#include <vector>

#include <google/protobuf/message.h>

#include "tiltcal/proto/stream.pb.h"

namespace tiltcal {

// (role, path) of one input, e.g. {"bag", "run1.bag"}.
using InputPath = std::pair<std::string, std::string>;

// Provenance of an output: producer, version, the exact params (text format),
// the inputs with their sizes, the creation time and the command line.
proto::Provenance MakeProvenance(const std::string& producer,
                                 const google::protobuf::Message& params,
                                 const std::vector<InputPath>& inputs,
                                 const std::string& command_line = "");

// Joins argv into one shell-like line for the provenance record.
std::string JoinCommandLine(int argc, const char* const* argv);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_PROVENANCE_H_
