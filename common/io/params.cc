#include "common/io/params.h"

#include <cmath>
#include <sstream>

#include "common/io/text_proto.h"
#include "tiltcal/proto/options.pb.h"

namespace tiltcal {

namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;
using google::protobuf::Reflection;

std::string FormatNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// Numeric value of a scalar field (or element `index` of a repeated one).
double NumericValue(const Message& message, const FieldDescriptor* field, int index) {
  const Reflection* r = message.GetReflection();
  const bool rep = field->is_repeated();
  switch (field->cpp_type()) {
    case FieldDescriptor::CPPTYPE_INT32:
      return rep ? r->GetRepeatedInt32(message, field, index) : r->GetInt32(message, field);
    case FieldDescriptor::CPPTYPE_INT64:
      return static_cast<double>(rep ? r->GetRepeatedInt64(message, field, index)
                                     : r->GetInt64(message, field));
    case FieldDescriptor::CPPTYPE_UINT32:
      return rep ? r->GetRepeatedUInt32(message, field, index) : r->GetUInt32(message, field);
    case FieldDescriptor::CPPTYPE_UINT64:
      return static_cast<double>(rep ? r->GetRepeatedUInt64(message, field, index)
                                     : r->GetUInt64(message, field));
    case FieldDescriptor::CPPTYPE_FLOAT:
      return rep ? r->GetRepeatedFloat(message, field, index) : r->GetFloat(message, field);
    case FieldDescriptor::CPPTYPE_DOUBLE:
      return rep ? r->GetRepeatedDouble(message, field, index) : r->GetDouble(message, field);
    default:
      return 0.0;
  }
}

bool IsNumeric(const FieldDescriptor* field) {
  switch (field->cpp_type()) {
    case FieldDescriptor::CPPTYPE_INT32:
    case FieldDescriptor::CPPTYPE_INT64:
    case FieldDescriptor::CPPTYPE_UINT32:
    case FieldDescriptor::CPPTYPE_UINT64:
    case FieldDescriptor::CPPTYPE_FLOAT:
    case FieldDescriptor::CPPTYPE_DOUBLE:
      return true;
    default:
      return false;
  }
}

Status CheckNumber(const std::string& name, double value, const FieldDescriptor* field) {
  const auto& options = field->options();
  if (!std::isfinite(value)) {
    return Status::Error("field " + name + " = " + FormatNumber(value) + " is not finite");
  }
  if (options.HasExtension(proto::min_value) && value < options.GetExtension(proto::min_value)) {
    return Status::Error("field " + name + " = " + FormatNumber(value) +
                         " is below its minimum " +
                         FormatNumber(options.GetExtension(proto::min_value)));
  }
  if (options.HasExtension(proto::max_value) && value > options.GetExtension(proto::max_value)) {
    return Status::Error("field " + name + " = " + FormatNumber(value) +
                         " is above its maximum " +
                         FormatNumber(options.GetExtension(proto::max_value)));
  }
  return Status::Ok();
}

Status Validate(const Message& message, const std::string& prefix) {
  const auto* descriptor = message.GetDescriptor();
  const Reflection* r = message.GetReflection();
  for (int i = 0; i < descriptor->field_count(); ++i) {
    const FieldDescriptor* field = descriptor->field(i);
    const std::string name = prefix + field->name();
    const bool required = field->options().GetExtension(proto::required);
    if (field->is_repeated()) {
      const int size = r->FieldSize(message, field);
      if (required && size == 0) return Status::Error("field " + name + " must not be empty");
      for (int k = 0; k < size; ++k) {
        const std::string element = name + "[" + std::to_string(k) + "]";
        if (IsNumeric(field)) {
          TILTCAL_RETURN_IF_ERROR(CheckNumber(element, NumericValue(message, field, k), field));
        } else if (field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
          TILTCAL_RETURN_IF_ERROR(
              Validate(r->GetRepeatedMessage(message, field, k), element + "."));
        }
      }
      continue;
    }
    if (IsNumeric(field)) {
      TILTCAL_RETURN_IF_ERROR(CheckNumber(name, NumericValue(message, field, 0), field));
    } else if (field->cpp_type() == FieldDescriptor::CPPTYPE_STRING) {
      if (required && r->GetString(message, field).empty()) {
        return Status::Error("field " + name + " must not be empty");
      }
    } else if (field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
      if (r->HasField(message, field)) {
        TILTCAL_RETURN_IF_ERROR(Validate(r->GetMessage(message, field), name + "."));
      } else if (required) {
        return Status::Error("field " + name + " is required");
      }
    }
  }
  return Status::Ok();
}

}  // namespace

Status ValidateAgainstSchema(const Message& message) { return Validate(message, ""); }

Status LoadParams(const std::string& path, Message* params) {
  TILTCAL_RETURN_IF_ERROR(ReadTextProto(path, params));
  return ValidateAgainstSchema(*params).WithContext(path);
}

Status LoadParamsOrDefaults(const std::string& path, std::string_view default_text,
                            Message* params) {
  if (!path.empty()) return LoadParams(path, params);
  const std::string source = "default " + params->GetDescriptor()->name();
  TILTCAL_RETURN_IF_ERROR(ParseTextProto(std::string(default_text), source, params));
  return ValidateAgainstSchema(*params).WithContext(source);
}

}  // namespace tiltcal
