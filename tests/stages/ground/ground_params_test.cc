// The cross-field rules of the ground params: the shipped defaults pass, and
// each rule rejects a violation with a message naming the field.
#include "stages/ground/ground_params.h"

#include <string>

#include <gtest/gtest.h>

#include "tests/stages/ground/ground_test_util.h"

namespace tiltcal::ground {
namespace {

using testing::DefaultGroundParams;
using testing::GroundParamsWith;

void ExpectRejected(const proto::GroundParams& params, const std::string& expected) {
  const Status status = ValidateGroundParams(params);
  ASSERT_FALSE(status.ok()) << "expected: " << expected;
  EXPECT_NE(status.message().find(expected), std::string::npos) << status.message();
}

TEST(GroundParams, DefaultsAreValid) {
  const Status status = ValidateGroundParams(DefaultGroundParams());
  EXPECT_TRUE(status.ok()) << status.message();
}

TEST(GroundParams, SchemaBoundsAreChecked) {
  proto::GroundParams two_inliers = DefaultGroundParams();
  two_inliers.mutable_gates()->set_min_inliers(2);
  ExpectRejected(two_inliers, "field gates.min_inliers = 2 is below its minimum 3");
  proto::GroundParams no_zone_model = DefaultGroundParams();
  no_zone_model.clear_zone_model();
  ExpectRejected(no_zone_model, "field zone_model is required");
}

TEST(GroundParams, ZoneModelRules) {
  ExpectRejected(GroundParamsWith("zone_model { min_range_m: 80 max_range_m: 80 }"),
                 "field zone_model.max_range_m must be greater than zone_model.min_range_m");
  proto::GroundParams params = DefaultGroundParams();
  params.mutable_zone_model()->add_rings(4);
  ExpectRejected(params, "field zone_model.rings must have exactly 4 values (one per zone), has 5");
  params = DefaultGroundParams();
  params.mutable_zone_model()->mutable_sectors()->RemoveLast();
  ExpectRejected(params,
                 "field zone_model.sectors must have exactly 4 values (one per zone), has 3");
  ExpectRejected(GroundParamsWith("zone_model { boundaries_m: [10, 20] }"),
                 "field zone_model.boundaries_m must have 0 or 3 values, has 2");
  ExpectRejected(GroundParamsWith("zone_model { boundaries_m: [10, 30, 20] }"),
                 "field zone_model.boundaries_m must increase strictly");
  ExpectRejected(GroundParamsWith("zone_model { boundaries_m: [10, 20, 90] }"),
                 "field zone_model.boundaries_m must increase strictly");
  const Status increasing =
      ValidateGroundParams(GroundParamsWith("zone_model { boundaries_m: [10, 20, 40] }"));
  EXPECT_TRUE(increasing.ok()) << increasing.message();
}

TEST(GroundParams, RegionFitNeedsElevationsForTheRingsOfInterest) {
  proto::GroundParams params = DefaultGroundParams();
  params.mutable_region_fit()->clear_near_elevation_m();
  ExpectRejected(params, "field region_fit.near_elevation_m needs at least one value");
  params.mutable_region_fit()->set_num_rings_of_interest(0);
  const Status status = ValidateGroundParams(params);
  EXPECT_TRUE(status.ok()) << status.message();
}

TEST(GroundParams, AutomaticFitRadiusNeedsAnOrderedRange) {
  ExpectRejected(GroundParamsWith("plane_fit { radius_min_m: 30 radius_max_m: 20 }"),
                 "field plane_fit.radius_max_m must be >= plane_fit.radius_min_m");
  ExpectRejected(GroundParamsWith("plane_fit { radius_min_m: 0 radius_max_m: 0 }"),
                 "field plane_fit.radius_max_m must be > 0 when plane_fit.radius_m is 0");
  // A fixed radius does not use the range.
  const Status fixed = ValidateGroundParams(
      GroundParamsWith("plane_fit { radius_m: 10 radius_min_m: 30 radius_max_m: 20 }"));
  EXPECT_TRUE(fixed.ok()) << fixed.message();
}

}  // namespace
}  // namespace tiltcal::ground
