#include "common/io/text_proto.h"

#include <filesystem>
#include <system_error>

#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/text_format.h>

#include "common/io/atomic_file.h"

namespace tiltcal {

namespace {

// Keeps the first parse error with its position (0-based from protobuf).
class FirstErrorCollector : public google::protobuf::io::ErrorCollector {
 public:
  void AddError(int line, int column, const std::string& message) override {
    if (error_.empty()) {
      error_ = "line " + std::to_string(line + 1) + ", column " + std::to_string(column + 1) +
               ": " + message;
    }
  }
  const std::string& error() const { return error_; }

 private:
  std::string error_;
};

}  // namespace

Status ParseTextProto(const std::string& text, const std::string& source_name,
                      google::protobuf::Message* message) {
  FirstErrorCollector errors;
  google::protobuf::TextFormat::Parser parser;
  parser.RecordErrorsTo(&errors);
  if (!parser.ParseFromString(text, message)) {
    return Status::Error(source_name + ": " +
                         (errors.error().empty() ? "cannot parse " +
                                                       message->GetDescriptor()->full_name()
                                                 : errors.error()));
  }
  return Status::Ok();
}

Status ReadTextProto(const std::string& path, google::protobuf::Message* message) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    return Status::Error(path + ": not a regular file (a " +
                         message->GetDescriptor()->name() + " in text format is expected)");
  }
  std::string text;
  TILTCAL_RETURN_IF_ERROR(ReadFileToString(path, &text));
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) {
    return Status::Error(path + ": empty file (a " + message->GetDescriptor()->name() +
                         " in text format is expected)");
  }
  return ParseTextProto(text, path, message);
}

Status WriteTextProto(const std::string& path, const google::protobuf::Message& message) {
  std::string text;
  google::protobuf::TextFormat::Printer printer;
  if (!printer.PrintToString(message, &text)) {
    return Status::Error(path + ": cannot format " + message.GetDescriptor()->full_name());
  }
  return WriteFileAtomically(path, text);
}

}  // namespace tiltcal
