#ifndef TILTCAL_STAGES_REPORT_MAP_PCD_H_
#define TILTCAL_STAGES_REPORT_MAP_PCD_H_

// Reads the before/after maps tiltcal_calibrate writes (map_export.h):
// binary PCD v0.7 whose first three fields are x y z (float32, count 1),
// any further fields skipped by their SIZE x COUNT.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace tiltcal::report {

// The points (frame a, m). Errors name the file and what is wrong: a
// header line missing or malformed, fields other than x y z first, not
// DATA binary, or fewer bytes than POINTS x the point size.
Status ReadMapPcd(const std::string& path, std::vector<Eigen::Vector3f>* points);

// The same from the file's bytes (exposed for tests); `path` names it in errors.
Status ParseMapPcd(const std::string& bytes, const std::string& path,
                   std::vector<Eigen::Vector3f>* points);

}  // namespace tiltcal::report

#endif  // TILTCAL_STAGES_REPORT_MAP_PCD_H_
