#ifndef TILTCAL_COMMON_IO_PARAMS_H_
#define TILTCAL_COMMON_IO_PARAMS_H_

#include <string>
#include <string_view>

#include <google/protobuf/message.h>

#include "common/status.h"

namespace tiltcal {

// Checks every field of `message` (recursively) against the bounds declared
// in the schema with the options of tiltcal/proto/options.proto (min_value,
// max_value, required) and rejects NaN / Inf. The error names the field by its
// dotted path, its value and the rule, e.g.
//   "field min_range_m = -1 is below its minimum 0".
Status ValidateAgainstSchema(const google::protobuf::Message& message);

// Reads a params file in text format and validates it. Every error names
// the file and the field.
Status LoadParams(const std::string& path, google::protobuf::Message* params);

// The params of a stage: the file at `path`, or, when `path` is empty, the
// stage's defaults `default_text` (its default_params.txtpb, compiled into the
// binary as <stage>::DefaultParamsText()). Validated like LoadParams.
Status LoadParamsOrDefaults(const std::string& path, std::string_view default_text,
                            google::protobuf::Message* params);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_PARAMS_H_
