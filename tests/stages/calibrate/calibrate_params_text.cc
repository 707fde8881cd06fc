#include "tests/stages/calibrate/calibrate_params_text.h"

#include <gtest/gtest.h>

#include "stages/calibrate/calibrate_params_validation.h"
#include "stages/calibrate/default_params_text.h"
#include "tests/testing/params_text.h"

namespace tiltcal::testing {

proto::CalibrateParams DefaultCalibrateParamsWith(const std::string& override_text) {
  const proto::CalibrateParams params =
      DefaultParamsWith<proto::CalibrateParams>(calibrate::DefaultParamsText(), override_text);
  const Status valid = calibrate::ValidateCalibrateParams(params);
  EXPECT_TRUE(valid.ok()) << valid.message();
  return params;
}

}  // namespace tiltcal::testing
