#include "stages/inspect/csv_table.h"

#include <charconv>

#include "common/io/csv_field.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal::inspect {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using google::protobuf::Message;

std::string FormatDouble(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

CsvTable::CsvTable(const Descriptor* type) {
  is_scan_ = type == proto::Scan::descriptor();
  AddColumns(type, "", {});
}

void CsvTable::AddColumns(const Descriptor* type, const std::string& prefix,
                          std::vector<const FieldDescriptor*> path) {
  for (int i = 0; i < type->field_count(); ++i) {
    const FieldDescriptor* field = type->field(i);
    if (field->is_repeated()) continue;
    auto field_path = path;
    field_path.push_back(field);
    const std::string name = prefix + field->name();
    if (field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
      AddColumns(field->message_type(), name + ".", field_path);
    } else {
      columns_.push_back({name, field_path});
    }
  }
}

std::string CsvTable::HeaderRow() const {
  std::string row;
  for (const Column& column : columns_) {
    if (!row.empty()) row += ',';
    row += column.name;
  }
  if (is_scan_) row += ",num_points";
  return row;
}

namespace {

std::string FormatScalar(const Message& message, const FieldDescriptor* field) {
  const auto* r = message.GetReflection();
  if (field->has_presence() && !r->HasField(message, field)) return "";  // unknown
  switch (field->cpp_type()) {
    case FieldDescriptor::CPPTYPE_INT32: return std::to_string(r->GetInt32(message, field));
    case FieldDescriptor::CPPTYPE_INT64: return std::to_string(r->GetInt64(message, field));
    case FieldDescriptor::CPPTYPE_UINT32: return std::to_string(r->GetUInt32(message, field));
    case FieldDescriptor::CPPTYPE_UINT64: return std::to_string(r->GetUInt64(message, field));
    case FieldDescriptor::CPPTYPE_FLOAT: return FormatDouble(r->GetFloat(message, field));
    case FieldDescriptor::CPPTYPE_DOUBLE: return FormatDouble(r->GetDouble(message, field));
    case FieldDescriptor::CPPTYPE_BOOL: return r->GetBool(message, field) ? "1" : "0";
    case FieldDescriptor::CPPTYPE_ENUM: return r->GetEnum(message, field)->name();
    case FieldDescriptor::CPPTYPE_STRING: return CsvField(r->GetString(message, field));
    case FieldDescriptor::CPPTYPE_MESSAGE: break;
  }
  return "";
}

}  // namespace

std::string CsvTable::Row(const Message& record) const {
  std::string row;
  bool first = true;
  for (const Column& column : columns_) {
    if (!first) row += ',';
    first = false;
    const Message* message = &record;
    for (size_t i = 0; i + 1 < column.path.size(); ++i) {
      message = &message->GetReflection()->GetMessage(*message, column.path[i]);
    }
    row += FormatScalar(*message, column.path.back());
  }
  if (is_scan_) {
    row += ',' + std::to_string(static_cast<const proto::Scan&>(record).x_size());
  }
  return row;
}

}  // namespace tiltcal::inspect
