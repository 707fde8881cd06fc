#include "stages/report/html_escape.h"

#include <fmt/format.h>

namespace tiltcal::report {

std::string EscapeHtml(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += ch;
    }
  }
  return out;
}

std::optional<std::string> RelativeHref(const std::string& path) {
  if (path.empty() || path[0] == '/') return std::nullopt;
  std::string href = path.rfind("../", 0) == 0 ? "" : "./";
  for (const char ch : path) {
    const auto c = static_cast<unsigned char>(ch);
    const bool unreserved = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                            (c >= '0' && c <= '9') || c == '-' || c == '.' || c == '_' ||
                            c == '~' || c == '/';
    href += unreserved ? std::string(1, ch) : fmt::format("%{:02X}", c);
  }
  return href;
}

std::string LinkOrText(const std::string& path, const std::string& attributes) {
  const std::optional<std::string> href = RelativeHref(path);
  if (!href) return EscapeHtml(path);
  return fmt::format("<a href=\"{}\"{}>{}</a>", *href, attributes, EscapeHtml(path));
}

}  // namespace tiltcal::report
