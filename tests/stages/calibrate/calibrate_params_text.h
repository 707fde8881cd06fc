#ifndef TILTCAL_TESTS_STAGES_CALIBRATE_CALIBRATE_PARAMS_TEXT_H_
#define TILTCAL_TESTS_STAGES_CALIBRATE_CALIBRATE_PARAMS_TEXT_H_

#include <string>

#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::testing {

// The calibrator's defaults (calibrate::DefaultParamsText()) with the fields
// of `override_text` (text format, CalibrateParams) merged over them
// (DefaultParamsWith, tests/testing/params_text.h); the test fails when the
// result breaks a schema bound or a rule of ValidateCalibrateParams.
proto::CalibrateParams DefaultCalibrateParamsWith(const std::string& override_text = "");

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_STAGES_CALIBRATE_CALIBRATE_PARAMS_TEXT_H_
