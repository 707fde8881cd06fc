#ifndef TILTCAL_TESTS_TESTING_ANGLES_H_
#define TILTCAL_TESTS_TESTING_ANGLES_H_

#include <cmath>

namespace tiltcal::testing {

inline constexpr double kDegToRad = M_PI / 180.0;

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_TESTING_ANGLES_H_
