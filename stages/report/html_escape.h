#ifndef TILTCAL_STAGES_REPORT_HTML_ESCAPE_H_
#define TILTCAL_STAGES_REPORT_HTML_ESCAPE_H_

// The page's one rule for strings from files, folder names and flags (the
// title, sequence names, verdict reasons, residual types, paths): they
// reach report.html and its inline SVG only through these functions, so
// they stay text and a link stays a relative link (stages/report/README.md,
// "Strings on the page").

#include <optional>
#include <string>

namespace tiltcal::report {

// `text` for HTML text or a double-quoted attribute value (inline SVG
// included): & < > " ' as character references.
std::string EscapeHtml(const std::string& text);

// The href of a link to the file `path`, given relative to the page: every
// byte but the unreserved characters of RFC 3986 (letters, digits, - . _ ~)
// and '/' percent-encoded, so that no scheme (javascript:), query or
// fragment can form, and "./" put in front unless it starts with "../".
// nullopt for a path that is not relative (empty, or starting with '/').
std::optional<std::string> RelativeHref(const std::string& path);

// <a href="RelativeHref(path)"{attributes}>path as text</a>, or the path as
// text alone when it is not relative. `attributes` is the page's own
// (e.g. " class=\"pcd\""), not escaped.
std::string LinkOrText(const std::string& path, const std::string& attributes = "");

}  // namespace tiltcal::report

#endif  // TILTCAL_STAGES_REPORT_HTML_ESCAPE_H_
