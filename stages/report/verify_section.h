#ifndef TILTCAL_STAGES_REPORT_VERIFY_SECTION_H_
#define TILTCAL_STAGES_REPORT_VERIFY_SECTION_H_

#include <string>

#include "tiltcal/proto/verify.pb.h"

namespace tiltcal::report {

// tiltcal_verify's out/verify.txtpb on the page.
struct VerifyPage {
  proto::VerifyResult result;
  std::string link;  // verify.txtpb relative to the page
};

// The section "Check against a stored calibration": the dataset's verdict
// (HOLDS, MOVED, CANNOT_TELL) and its reasons, the reference's path, and per
// sequence its verdict, chi^2 / limit (dof), the rotation, translation and
// tau differences with their sigma, the smallest moves it detects, the map
// thickness with the estimate and with the reference, and its reasons.
// Every string from the file is escaped (html_escape.h).
std::string VerifySection(const VerifyPage& verify);

}  // namespace tiltcal::report

#endif  // TILTCAL_STAGES_REPORT_VERIFY_SECTION_H_
