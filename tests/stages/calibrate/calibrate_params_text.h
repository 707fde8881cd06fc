#ifndef TILTCAL_TESTS_STAGES_CALIBRATE_CALIBRATE_PARAMS_TEXT_H_
#define TILTCAL_TESTS_STAGES_CALIBRATE_CALIBRATE_PARAMS_TEXT_H_

#include <string>

#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::testing {

// The program's defaults (stages/calibrate/default_params.txtpb) with the
// fields of `override_text` (text format, CalibrateParams) merged over them;
// the test fails (ADD_FAILURE) when either does not parse or validate.
proto::CalibrateParams DefaultCalibrateParamsWith(const std::string& override_text = "");

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_STAGES_CALIBRATE_CALIBRATE_PARAMS_TEXT_H_
