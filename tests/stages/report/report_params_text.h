#ifndef TILTCAL_TESTS_STAGES_REPORT_REPORT_PARAMS_TEXT_H_
#define TILTCAL_TESTS_STAGES_REPORT_REPORT_PARAMS_TEXT_H_

#include "stages/report/default_params_text.h"
#include "tests/testing/params_text.h"
#include "tiltcal/proto/report_params.pb.h"

namespace tiltcal::report {

// stages/report/default_params.txtpb, validated.
inline proto::ReportParams DefaultReportParams() {
  return testing::DefaultParamsWith<proto::ReportParams>(DefaultParamsText());
}

}  // namespace tiltcal::report

#endif  // TILTCAL_TESTS_STAGES_REPORT_REPORT_PARAMS_TEXT_H_
