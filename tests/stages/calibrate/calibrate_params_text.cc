#include "tests/stages/calibrate/calibrate_params_text.h"

#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include "common/io/params.h"
#include "stages/calibrate/calibrate_params_validation.h"
#include "tests/testing/test_env.h"

namespace tiltcal::testing {

proto::CalibrateParams DefaultCalibrateParamsWith(const std::string& override_text) {
  proto::CalibrateParams params;
  const Status loaded = LoadParams(
      SourceDir() + "/stages/calibrate/default_params.txtpb", &params);
  if (!loaded.ok()) ADD_FAILURE() << loaded.message();
  if (!google::protobuf::TextFormat::MergeFromString(override_text, &params)) {
    ADD_FAILURE() << "override text does not parse: " << override_text;
  }
  Status valid = ValidateAgainstSchema(params);
  if (valid.ok()) valid = calibrate::ValidateCalibrateParams(params);
  if (!valid.ok()) ADD_FAILURE() << valid.message();
  return params;
}

}  // namespace tiltcal::testing
