#ifndef TILTCAL_TESTS_STAGES_GROUND_GROUND_TEST_UTIL_H_
#define TILTCAL_TESTS_STAGES_GROUND_GROUND_TEST_UTIL_H_

#include <cmath>
#include <string>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "common/io/eigen_proto.h"
#include "stages/ground/default_params_text.h"
#include "tests/testing/params_text.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/ground_params.pb.h"

namespace tiltcal::testing {

// The shipped defaults (stages/ground/default_params.txtpb, compiled in).
inline proto::GroundParams DefaultGroundParams() {
  return DefaultParamsWith<proto::GroundParams>(ground::DefaultParamsText());
}

// The shipped defaults with `override_text` (text format) merged over them:
// a singular field replaces the default, a repeated one is appended to.
inline proto::GroundParams GroundParamsWith(const std::string& override_text) {
  return DefaultParamsWith<proto::GroundParams>(ground::DefaultParamsText(), override_text);
}

inline Eigen::Vector3d NormalOf(const proto::GroundPlane& plane) {
  return ToEigen(plane.normal_in_lidar());
}

// Every floating-point field of the plane is finite.
inline ::testing::AssertionResult NoNan(const proto::GroundPlane& p) {
  const double values[] = {p.normal_in_lidar().x(), p.normal_in_lidar().y(),
                           p.normal_in_lidar().z(), p.height_m(), p.rms_m(),
                           p.azimuth_coverage(), p.tilt_deg(), p.centroid_in_lidar().x(),
                           p.centroid_in_lidar().y(), p.centroid_in_lidar().z(),
                           p.eigenvalue_min(), p.eigenvalue_mid(), p.eigenvalue_max(),
                           p.fit_radius_m(), p.height_prior_m(), p.tilt_jump_deg(),
                           p.ground_reference_z_m(), p.radial_spread_ratio(),
                           p.normal_std_deg(), p.height_std_m()};
  for (double v : values) {
    if (!std::isfinite(v)) return ::testing::AssertionFailure() << "non-finite field";
  }
  for (double v : p.covariance()) {
    if (!std::isfinite(v)) return ::testing::AssertionFailure() << "non-finite covariance";
  }
  if (p.covariance_size() != 0 && p.covariance_size() != 16) {
    return ::testing::AssertionFailure() << "covariance has " << p.covariance_size() << " values";
  }
  return ::testing::AssertionSuccess();
}

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_STAGES_GROUND_GROUND_TEST_UTIL_H_
