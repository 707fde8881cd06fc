#include "common/io/escaping.h"

#include <cstdint>

#include <fmt/format.h>

namespace tiltcal {
namespace {

// One UTF-8 character of `text` at `i`: its code point and length, or
// valid = false (length 1) for a byte that does not start a well-formed
// sequence (RFC 3629: no overlong forms, no surrogates, at most U+10FFFF).
struct Utf8Char {
  uint32_t code_point = 0;
  size_t length = 1;
  bool valid = false;
};

Utf8Char DecodeAt(const std::string& text, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char lead = byte(i);
  if (lead < 0x80) return {lead, 1, true};
  size_t length = 0;
  uint32_t code_point = 0, minimum = 0;
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2, code_point = lead & 0x1F, minimum = 0x80;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3, code_point = lead & 0x0F, minimum = 0x800;
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4, code_point = lead & 0x07, minimum = 0x10000;
  } else {
    return {};
  }
  if (i + length > text.size()) return {};
  for (size_t k = 1; k < length; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return {};
    code_point = (code_point << 6) | (byte(i + k) & 0x3F);
  }
  if (code_point < minimum || code_point > 0x10FFFF ||
      (code_point >= 0xD800 && code_point <= 0xDFFF)) {
    return {};
  }
  return {code_point, length, true};
}

// Characters no export may carry raw: controls (C0 but newline, DEL, C1),
// the Unicode line and paragraph separators, the non-characters U+FFFE and
// U+FFFF.
bool MustEscape(uint32_t c) {
  return (c < 0x20 && c != '\n') || (c >= 0x7F && c <= 0x9F) || c == 0x2028 || c == 0x2029 ||
         c == 0xFFFE || c == 0xFFFF;
}

// The visible form of a character MustEscape holds, or of an invalid byte.
std::string Visible(const Utf8Char& ch, unsigned char byte) {
  if (!ch.valid) return fmt::format("\\x{:02x}", byte);
  switch (ch.code_point) {
    case '\t': return "\\t";
    case '\r': return "\\r";
    default: break;
  }
  return ch.code_point < 0x80 ? fmt::format("\\x{:02x}", ch.code_point)
                              : fmt::format("\\u{:04x}", ch.code_point);
}

// `text` with every character MustEscape holds, and every invalid byte,
// shown visibly; newlines kept.
std::string ShowControls(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    const Utf8Char ch = DecodeAt(text, i);
    if (!ch.valid || MustEscape(ch.code_point)) {
      out += Visible(ch, static_cast<unsigned char>(text[i]));
    } else {
      out.append(text, i, ch.length);
    }
    i += ch.length;
  }
  return out;
}

}  // namespace

std::string CommentLines(const std::string& text, const std::string& prefix) {
  const std::string shown = ShowControls(text);
  std::string out;
  size_t start = 0;
  while (true) {
    const size_t end = shown.find('\n', start);
    out += prefix + shown.substr(start, end - start) + "\n";
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return out;
}

std::string XmlComment(const std::string& text) {
  std::string body = CommentLines(text, "  ");
  for (size_t i = body.find("--"); i != std::string::npos; i = body.find("--", i)) {
    body.replace(i, 2, "- -");
  }
  return "<!--\n" + body + "-->\n";
}

std::string ShellWord(const std::string& text) {
  bool plain = !text.empty();
  for (const char c : text) {
    const bool safe = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      std::string_view("_@%+=:,./-").find(c) != std::string_view::npos;
    plain = plain && safe;
  }
  if (plain) return text;
  std::string out = "'";
  for (const char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string QuotedString(const std::string& text) {
  std::string out = "\"";
  for (size_t i = 0; i < text.size();) {
    const Utf8Char ch = DecodeAt(text, i);
    const uint32_t c = ch.valid ? ch.code_point : 0xFFFD;
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (!ch.valid || MustEscape(c)) {
      out += fmt::format("\\u{:04x}", c);
    } else {
      out.append(text, i, ch.length);
    }
    i += ch.length;
  }
  return out + "\"";
}

std::string XmlAttribute(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    const Utf8Char ch = DecodeAt(text, i);
    switch (ch.valid ? ch.code_point : 0xFFFD) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      case '\t': out += "&#9;"; break;
      case '\n': out += "&#10;"; break;
      case '\r': out += "&#13;"; break;
      default:
        if (!ch.valid || (ch.code_point < 0x20 || ch.code_point == 0xFFFE ||
                          ch.code_point == 0xFFFF)) {
          out += Visible(ch, static_cast<unsigned char>(text[i]));
        } else {
          out.append(text, i, ch.length);
        }
    }
    i += ch.length;
  }
  return out;
}

}  // namespace tiltcal
