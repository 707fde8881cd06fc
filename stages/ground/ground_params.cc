#include "stages/ground/ground_params.h"

#include <string>

#include "common/io/params.h"
#include "stages/ground/ground_segmentation.h"

namespace tiltcal::ground {

Status ValidateZoneModelParams(const proto::ZoneModelParams& zone_model) {
  if (!(zone_model.max_range_m() > zone_model.min_range_m())) {
    return Status::Error(
        "field zone_model.max_range_m must be greater than zone_model.min_range_m");
  }
  if (zone_model.rings_size() != 4) {
    return Status::Error(
        "field zone_model.rings must have exactly 4 values (one per zone), has " +
        std::to_string(zone_model.rings_size()));
  }
  if (zone_model.sectors_size() != 4) {
    return Status::Error(
        "field zone_model.sectors must have exactly 4 values (one per zone), has " +
        std::to_string(zone_model.sectors_size()));
  }
  if (zone_model.boundaries_m_size() != 0 && zone_model.boundaries_m_size() != 3) {
    return Status::Error("field zone_model.boundaries_m must have 0 or 3 values, has " +
                         std::to_string(zone_model.boundaries_m_size()));
  }
  double bound_m[5];
  ZoneBoundaries(zone_model, bound_m);
  for (int k = 0; k < 4; ++k) {
    if (!(bound_m[k + 1] > bound_m[k])) {
      return Status::Error(
          "field zone_model.boundaries_m must increase strictly between "
          "zone_model.min_range_m and zone_model.max_range_m");
    }
  }
  return Status::Ok();
}

Status ValidateRegionFitParams(const proto::RegionFitParams& region_fit) {
  if (region_fit.num_rings_of_interest() > 0 && region_fit.near_elevation_m_size() == 0) {
    return Status::Error(
        "field region_fit.near_elevation_m needs at least one value when "
        "region_fit.num_rings_of_interest > 0");
  }
  return Status::Ok();
}

Status ValidateScanPlaneFitParams(const proto::ScanPlaneFitParams& plane_fit) {
  if (plane_fit.radius_m() != 0.0) return Status::Ok();
  if (!(plane_fit.radius_max_m() >= plane_fit.radius_min_m())) {
    return Status::Error("field plane_fit.radius_max_m must be >= plane_fit.radius_min_m");
  }
  if (!(plane_fit.radius_max_m() > 0.0)) {
    return Status::Error(
        "field plane_fit.radius_max_m must be > 0 when plane_fit.radius_m is 0 (automatic)");
  }
  return Status::Ok();
}

Status ValidateGroundParams(const proto::GroundParams& params) {
  TILTCAL_RETURN_IF_ERROR(ValidateAgainstSchema(params));
  TILTCAL_RETURN_IF_ERROR(ValidateZoneModelParams(params.zone_model()));
  TILTCAL_RETURN_IF_ERROR(ValidateRegionFitParams(params.region_fit()));
  return ValidateScanPlaneFitParams(params.plane_fit());
}

}  // namespace tiltcal::ground
