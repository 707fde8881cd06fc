#ifndef TILTCAL_COMMON_IO_ESCAPING_H_
#define TILTCAL_COMMON_IO_ESCAPING_H_

// How a string from the calibration or the command line (the source path,
// the verdict reasons, the frame names) enters each export syntax: one rule
// per position, so that it stays data whatever it holds (newlines, quotes,
// "-->", shell or YAML syntax). stages/export/README.md, "Strings in the
// exports".

#include <string>

namespace tiltcal {

// `text` as comment lines: one line per line of `text` (split at '\n'),
// each `prefix` + the line + '\n' ("" gives one empty comment line). Every
// other character that could end a line or that a consumer refuses is
// shown as an escape instead: C0 controls and DEL as \t, \r or \xNN, the
// C1 controls and U+2028, U+2029, U+FFFE, U+FFFF (line breaks or
// non-printable to YAML) as \uNNNN, bytes that are not UTF-8 as \xNN.
std::string CommentLines(const std::string& text, const std::string& prefix);

// An XML comment holding `text` as CommentLines with the prefix "  ",
// "--" written "- -" (XML comments may not contain it): "<!--\n...-->\n".
std::string XmlComment(const std::string& text);

// One word of a POSIX shell command line: as is when it is not empty and
// only has letters, digits and _ @ % + = : , . / -; otherwise in single
// quotes, each ' written '\''.
std::string ShellWord(const std::string& text);

// A double-quoted string that JSON and YAML (1.1 and 1.2) both read back as
// `text`: " and \ escaped, \n \r \t, the other C0 controls, DEL, the C1
// controls and U+2028, U+2029, U+FFFE, U+FFFF as \uNNNN; a byte that is not
// UTF-8 becomes U+FFFD (\ufffd), the one change of value.
std::string QuotedString(const std::string& text);

// A double-quoted XML attribute value: & < > " ' as entities, tab, newline
// and carriage return as character references; characters XML 1.0 cannot
// hold (the other controls, U+FFFE, U+FFFF, non-UTF-8 bytes) shown as in
// CommentLines.
std::string XmlAttribute(const std::string& text);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_ESCAPING_H_
