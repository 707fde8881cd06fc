#ifndef TILTCAL_TESTS_TESTING_PARAMS_TEXT_H_
#define TILTCAL_TESTS_TESTING_PARAMS_TEXT_H_

#include <string>
#include <string_view>

#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include "common/io/params.h"
#include "common/io/text_proto.h"

namespace tiltcal::testing {

// Params written as text in the test, so that no test runs on values hidden
// in C++ defaults. Fails the test when the text does not parse or breaks a
// bound of the schema.
template <typename Params>
Params ParamsFromText(const std::string& text) {
  Params params;
  const Status parsed = ParseTextProto(text, "test params", &params);
  EXPECT_TRUE(parsed.ok()) << parsed.message();
  const Status valid = ValidateAgainstSchema(params);
  EXPECT_TRUE(valid.ok()) << valid.message();
  return params;
}

// A stage's defaults (its DefaultParamsText()) with `overrides` merged over
// them in text format: a singular field given in `overrides` replaces the
// default, a repeated one is appended to (clear it in code to replace it).
template <typename Params>
Params DefaultParamsWith(std::string_view default_text, const std::string& overrides = "") {
  Params params = ParamsFromText<Params>(std::string(default_text));
  google::protobuf::TextFormat::Parser parser;
  EXPECT_TRUE(parser.MergeFromString(overrides, &params)) << "cannot parse: " << overrides;
  const Status valid = ValidateAgainstSchema(params);
  EXPECT_TRUE(valid.ok()) << valid.message();
  return params;
}

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_TESTING_PARAMS_TEXT_H_
