#ifndef TILTCAL_STAGES_REPORT_BASE64_H_
#define TILTCAL_STAGES_REPORT_BASE64_H_

#include <string>

namespace tiltcal::report {

// Base64 (RFC 4648 §4, with '=' padding) of `bytes`, for data: URIs.
std::string EncodeBase64(const std::string& bytes);

}  // namespace tiltcal::report

#endif  // TILTCAL_STAGES_REPORT_BASE64_H_
