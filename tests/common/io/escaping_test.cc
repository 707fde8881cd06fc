#include "common/io/escaping.h"

#include <string>

#include <gtest/gtest.h>

namespace tiltcal {
namespace {

TEST(CommentLines, OneLinePerInputLineEachPrefixed) {
  EXPECT_EQ(CommentLines("one", "# "), "# one\n");
  EXPECT_EQ(CommentLines("", "# "), "# \n");
  EXPECT_EQ(CommentLines("one\ntwo\n", "# "), "# one\n# two\n# \n");
  EXPECT_EQ(CommentLines("a\nrm -rf x", "  "), "  a\n  rm -rf x\n");
}

TEST(CommentLines, ControlsAndLineSeparatorsShownVisibly) {
  EXPECT_EQ(CommentLines("a\rb\tc\x01" "d\x1b\x7f", "# "), "# a\\rb\\tc\\x01d\\x1b\\x7f\n");
  // U+0085 (NEL), U+2028, U+2029 end a line in YAML; U+FFFE is no character.
  EXPECT_EQ(CommentLines("a\xc2\x85" "b\xe2\x80\xa8" "c\xe2\x80\xa9" "d\xef\xbf\xbe", "# "),
            "# a\\u0085b\\u2028c\\u2029d\\ufffe\n");
  // Other UTF-8 is kept; bytes that are not UTF-8 are shown.
  EXPECT_EQ(CommentLines("\xc3\xa9 \xce\xb8 \xf0\x9f\x99\x82", "# "),
            "# \xc3\xa9 \xce\xb8 \xf0\x9f\x99\x82\n");
  EXPECT_EQ(CommentLines("a\xff" "b\xc3", "# "), "# a\\xffb\\xc3\n");
  EXPECT_EQ(CommentLines("\xc0\xaf \xed\xa0\x80", "# "), "# \\xc0\\xaf \\xed\\xa0\\x80\n");
}

TEST(XmlComment, NoDoubleHyphenInside) {
  EXPECT_EQ(XmlComment("a --> b\n<!-- c"), "<!--\n  a - -> b\n  <!- - c\n-->\n");
  EXPECT_EQ(XmlComment("---"), "<!--\n  - - -\n-->\n");
}

TEST(ShellWord, PlainOrSingleQuoted) {
  EXPECT_EQ(ShellWord("imu_link"), "imu_link");
  EXPECT_EQ(ShellWord("base/lidar-0.1,x=y:z@h%+"), "base/lidar-0.1,x=y:z@h%+");
  EXPECT_EQ(ShellWord(""), "''");
  EXPECT_EQ(ShellWord("a b"), "'a b'");
  EXPECT_EQ(ShellWord("x; touch y"), "'x; touch y'");
  EXPECT_EQ(ShellWord("$(id)`id`\n"), "'$(id)`id`\n'");
  EXPECT_EQ(ShellWord("it's"), "'it'\\''s'");
}

TEST(QuotedString, JsonAndYamlEscapes) {
  EXPECT_EQ(QuotedString("lidar_link"), "\"lidar_link\"");
  EXPECT_EQ(QuotedString("null"), "\"null\"");
  EXPECT_EQ(QuotedString("a\"b\\c\nd\re\tf"), "\"a\\\"b\\\\c\\nd\\re\\tf\"");
  EXPECT_EQ(QuotedString("\x01\x7f\xc2\x85\xe2\x80\xa8\xc3\xa9"),
            "\"\\u0001\\u007f\\u0085\\u2028\xc3\xa9\"");
  EXPECT_EQ(QuotedString("a\xff"), "\"a\\ufffd\"");
}

TEST(XmlAttribute, EntitiesAndReferences) {
  EXPECT_EQ(XmlAttribute("imu_link"), "imu_link");
  EXPECT_EQ(XmlAttribute("a&b<c>d\"e'f"), "a&amp;b&lt;c&gt;d&quot;e&apos;f");
  EXPECT_EQ(XmlAttribute("a\tb\nc\rd\x01"), "a&#9;b&#10;c&#13;d\\x01");
}

}  // namespace
}  // namespace tiltcal
