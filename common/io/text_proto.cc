#include "common/io/text_proto.h"

#include <cctype>
#include <filesystem>
#include <map>
#include <system_error>
#include <utility>
#include <vector>

#include <google/protobuf/descriptor.h>
#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
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

class SilentErrorCollector : public google::protobuf::io::ErrorCollector {
 public:
  void AddError(int, int, const std::string&) override {}
};

std::string Position(int line, int column) {
  return "line " + std::to_string(line + 1) + ", column " + std::to_string(column + 1);
}

// protobuf's parser refuses a non-repeated field given twice only when the
// first value is present; in proto3 a scalar at its default (0, false, "")
// is not, so "x: 0  x: 5" would silently keep 5. This walks the tokens of the
// text once, message by message (field name, optional ':', then a scalar, a
// list [...] or a nested message {...} / <...>), and names the first
// non-repeated field seen twice within one message: "line L, column C: field
// a.b is given twice (first at line L0, column C0)". Text it does not follow
// (a syntax error) ends the walk without a finding; the parser reports it.
std::string FindDuplicateField(const std::string& text,
                               const google::protobuf::Descriptor* root) {
  using google::protobuf::Descriptor;
  using google::protobuf::FieldDescriptor;
  using google::protobuf::io::Tokenizer;
  google::protobuf::io::ArrayInputStream input(text.data(), static_cast<int>(text.size()));
  SilentErrorCollector ignored;
  Tokenizer tokens(&input, &ignored);
  tokens.set_allow_f_after_float(true);
  tokens.set_comment_style(Tokenizer::SH_COMMENT_STYLE);
  tokens.set_require_space_after_number(false);
  tokens.set_allow_multiline_strings(true);
  struct Message {
    const Descriptor* type;  // nullptr: not known (its fields are not checked)
    std::string path;        // "a.b." of its fields
    std::map<const FieldDescriptor*, std::pair<int, int>> seen;  // line, column
  };
  std::vector<Message> stack = {{root, "", {}}};
  const auto is = [&tokens](const char* symbol) {
    return tokens.current().type == Tokenizer::TYPE_SYMBOL && tokens.current().text == symbol;
  };
  const auto skip_separator = [&] {
    if (is(";") || is(",")) tokens.Next();
  };
  tokens.Next();
  while (tokens.current().type != Tokenizer::TYPE_END) {
    if (is("}") || is(">")) {
      if (stack.size() == 1) return "";
      stack.pop_back();
      tokens.Next();
      skip_separator();
      continue;
    }
    Message& message = stack.back();
    const int line = tokens.current().line, column = tokens.current().column;
    std::string name;
    const FieldDescriptor* field = nullptr;
    const Descriptor* nested = nullptr;
    if (is("[")) {  // an extension [pkg.ext] or an Any [type.googleapis.com/pkg.Type]
      for (tokens.Next(); !is("]"); tokens.Next()) {
        if (tokens.current().type == Tokenizer::TYPE_END) return "";
        name += tokens.current().text;
      }
      tokens.Next();
      const auto* pool = root->file()->pool();
      const size_t slash = name.rfind('/');
      if (slash != std::string::npos) {
        nested = pool->FindMessageTypeByName(name.substr(slash + 1));
      } else {
        field = pool->FindExtensionByName(name);
      }
      name = "[" + name + "]";
    } else if (tokens.current().type == Tokenizer::TYPE_IDENTIFIER) {
      name = tokens.current().text;
      if (message.type != nullptr) {
        field = message.type->FindFieldByName(name);
        if (field == nullptr) {  // a group is named by its type
          std::string lower = name;
          for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
          field = message.type->FindFieldByLowercaseName(lower);
          if (field != nullptr && field->type() != FieldDescriptor::TYPE_GROUP) field = nullptr;
        }
      }
      tokens.Next();
    } else {
      return "";
    }
    if (field != nullptr && !field->is_repeated()) {
      const auto [first, inserted] = message.seen.emplace(field, std::make_pair(line, column));
      if (!inserted) {
        return Position(line, column) + ": field " + message.path + name +
               " is given twice (first at " + Position(first->second.first, first->second.second) +
               ")";
      }
    }
    if (field != nullptr && field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
      nested = field->message_type();
    }
    if (is(":")) tokens.Next();
    if (is("{") || is("<")) {
      stack.push_back({nested, message.path + name + ".", {}});
      tokens.Next();
      continue;
    }
    if (is("[")) {  // a list: skipped with its nested messages
      int depth = 0;
      do {
        if (is("[") || is("{") || is("<")) ++depth;
        if (is("]") || is("}") || is(">")) --depth;
        if (tokens.current().type == Tokenizer::TYPE_END) return "";
        tokens.Next();
      } while (depth > 0);
    } else if (is("-")) {
      tokens.Next();
      tokens.Next();
    } else if (tokens.current().type == Tokenizer::TYPE_STRING) {
      while (tokens.current().type == Tokenizer::TYPE_STRING) tokens.Next();
    } else {
      tokens.Next();
    }
    skip_separator();
  }
  return "";
}

}  // namespace

Status ParseTextProto(const std::string& text, const std::string& source_name,
                      google::protobuf::Message* message) {
  const std::string duplicate = FindDuplicateField(text, message->GetDescriptor());
  if (!duplicate.empty()) return Status::Error(source_name + ": " + duplicate);
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
