#ifndef TILTCAL_STAGES_GROUND_GROUND_PARAMS_H_
#define TILTCAL_STAGES_GROUND_GROUND_PARAMS_H_

#include "common/status.h"
#include "tiltcal/proto/ground_params.pb.h"

namespace tiltcal::ground {

// The rules of the ground params that the schema bounds
// (proto/tiltcal/proto/ground_params.proto) cannot express, one function per
// message. Each error names the field by its path in GroundParams.

// rings and sectors have exactly 4 values; max_range_m > min_range_m;
// boundaries_m has 0 or 3 values and the zone boundaries increase strictly.
Status ValidateZoneModelParams(const proto::ZoneModelParams& zone_model);

// near_elevation_m has a value when num_rings_of_interest > 0.
Status ValidateRegionFitParams(const proto::RegionFitParams& region_fit);

// With an automatic fit radius (radius_m = 0): radius_max_m > 0 and
// radius_max_m >= radius_min_m.
Status ValidateScanPlaneFitParams(const proto::ScanPlaneFitParams& plane_fit);

// The schema bounds of every field, then the rules above.
Status ValidateGroundParams(const proto::GroundParams& params);

}  // namespace tiltcal::ground

#endif  // TILTCAL_STAGES_GROUND_GROUND_PARAMS_H_
