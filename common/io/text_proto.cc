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
class DuplicateFieldFinder {
 public:
  using Descriptor = google::protobuf::Descriptor;
  using FieldDescriptor = google::protobuf::FieldDescriptor;
  using Tokenizer = google::protobuf::io::Tokenizer;

  DuplicateFieldFinder(const std::string& text, const Descriptor* root)
      : input_(text.data(), static_cast<int>(text.size())),
        tokens_(&input_, &ignored_),
        root_(root) {
    tokens_.set_allow_f_after_float(true);
    tokens_.set_comment_style(Tokenizer::SH_COMMENT_STYLE);
    tokens_.set_require_space_after_number(false);
    tokens_.set_allow_multiline_strings(true);
  }

  // The finding, "" without one.
  std::string Find() {
    std::vector<Message> stack = {{root_, "", {}}};
    tokens_.Next();
    while (tokens_.current().type != Tokenizer::TYPE_END) {
      if (Is("}") || Is(">")) {
        if (stack.size() == 1) return "";
        stack.pop_back();
        tokens_.Next();
        SkipSeparator();
        continue;
      }
      Message& message = stack.back();
      const int line = tokens_.current().line, column = tokens_.current().column;
      FieldName field;
      if (!ReadFieldName(message, &field)) return "";
      if (field.field != nullptr && !field.field->is_repeated()) {
        const auto [first, inserted] =
            message.seen.emplace(field.field, std::make_pair(line, column));
        if (!inserted) {
          return Position(line, column) + ": field " + message.path + field.name +
                 " is given twice (first at " +
                 Position(first->second.first, first->second.second) + ")";
        }
      }
      if (field.field != nullptr && field.field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
        field.nested = field.field->message_type();
      }
      if (Is(":")) tokens_.Next();
      if (Is("{") || Is("<")) {
        stack.push_back({field.nested, message.path + field.name + ".", {}});
        tokens_.Next();
        continue;
      }
      if (!SkipValue()) return "";
      SkipSeparator();
    }
    return "";
  }

 private:
  struct Message {
    const Descriptor* type;  // nullptr: not known (its fields are not checked)
    std::string path;        // "a.b." of its fields
    std::map<const FieldDescriptor*, std::pair<int, int>> seen;  // line, column
  };
  // The name of a field as written, and what it names.
  struct FieldName {
    std::string name;
    const FieldDescriptor* field = nullptr;
    const Descriptor* nested = nullptr;  // the type of an Any's value
  };

  bool Is(const char* symbol) {
    return tokens_.current().type == Tokenizer::TYPE_SYMBOL && tokens_.current().text == symbol;
  }
  void SkipSeparator() {
    if (Is(";") || Is(",")) tokens_.Next();
  }

  // Reads the field name at the current token: an identifier, an extension
  // [pkg.ext] or an Any [type.googleapis.com/pkg.Type]. False for text the
  // walk does not follow.
  bool ReadFieldName(const Message& message, FieldName* out) {
    if (Is("[")) {
      std::string name;
      for (tokens_.Next(); !Is("]"); tokens_.Next()) {
        if (tokens_.current().type == Tokenizer::TYPE_END) return false;
        name += tokens_.current().text;
      }
      tokens_.Next();
      const auto* pool = root_->file()->pool();
      const size_t slash = name.rfind('/');
      if (slash != std::string::npos) {
        out->nested = pool->FindMessageTypeByName(name.substr(slash + 1));
      } else {
        out->field = pool->FindExtensionByName(name);
      }
      out->name = "[" + name + "]";
      return true;
    }
    if (tokens_.current().type != Tokenizer::TYPE_IDENTIFIER) return false;
    out->name = tokens_.current().text;
    if (message.type != nullptr) out->field = FindField(*message.type, out->name);
    tokens_.Next();
    return true;
  }

  // The field `name` of `type`; a group is named by its type.
  static const FieldDescriptor* FindField(const Descriptor& type, const std::string& name) {
    const FieldDescriptor* field = type.FindFieldByName(name);
    if (field != nullptr) return field;
    std::string lower = name;
    for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    field = type.FindFieldByLowercaseName(lower);
    if (field != nullptr && field->type() != FieldDescriptor::TYPE_GROUP) return nullptr;
    return field;
  }

  // Skips a value that is not a message: a list (with its nested messages),
  // a negative number, adjacent strings or one token. False when the text
  // ends inside a list.
  bool SkipValue() {
    if (Is("[")) {
      int depth = 0;
      do {
        if (Is("[") || Is("{") || Is("<")) ++depth;
        if (Is("]") || Is("}") || Is(">")) --depth;
        if (tokens_.current().type == Tokenizer::TYPE_END) return false;
        tokens_.Next();
      } while (depth > 0);
    } else if (Is("-")) {
      tokens_.Next();
      tokens_.Next();
    } else if (tokens_.current().type == Tokenizer::TYPE_STRING) {
      while (tokens_.current().type == Tokenizer::TYPE_STRING) tokens_.Next();
    } else {
      tokens_.Next();
    }
    return true;
  }

  google::protobuf::io::ArrayInputStream input_;
  SilentErrorCollector ignored_;
  Tokenizer tokens_;
  const Descriptor* root_;
};

std::string FindDuplicateField(const std::string& text,
                               const google::protobuf::Descriptor* root) {
  return DuplicateFieldFinder(text, root).Find();
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
