#include "common/io/csv_field.h"

#include <gtest/gtest.h>

namespace tiltcal {
namespace {

// RFC 4180: quoted when it holds a comma, a quote, CR or LF; quotes doubled.
TEST(CsvField, QuotesOnlyWhenNeeded) {
  EXPECT_EQ(CsvField("run1"), "run1");
  EXPECT_EQ(CsvField(""), "");
  EXPECT_EQ(CsvField("a b;c"), "a b;c");
  EXPECT_EQ(CsvField("a,b"), "\"a,b\"");
  EXPECT_EQ(CsvField("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(CsvField("a\nb"), "\"a\nb\"");
  EXPECT_EQ(CsvField("a\rb"), "\"a\rb\"");
}

}  // namespace
}  // namespace tiltcal
