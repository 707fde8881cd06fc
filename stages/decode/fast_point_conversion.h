#ifndef TILTCAL_STAGES_DECODE_FAST_POINT_CONVERSION_H_
#define TILTCAL_STAGES_DECODE_FAST_POINT_CONVERSION_H_

// One loop per common PointCloud2 layout, types fixed at compile time: no
// per-point type switch and no libm call. Every value is computed exactly as
// in the loop of any layout (ConvertPointCloud2ToScan: same double
// intermediates, same checks in the same order), so both give the same
// bytes. Which layouts: PointConversionOptions::allow_fast_path.

#include <cstdint>

#include "bag/ros1/messages.h"
#include "stages/decode/point_field_layout.h"

namespace tiltcal::decode {

// The Scan columns the loops write, one value per kept point.
struct FastColumns {
  float* x;
  float* y;
  float* z;
  float* intensity;
  uint32_t* ring;  // null when the cloud has no ring field
  int32_t* time_offset_ns;
};

// The points kept and dropped.
struct FastResult {
  int count = 0;
  uint32_t dropped_invalid = 0;
  uint32_t dropped_range = 0;
};

// Converts all points of `cloud` into `out`; false when a time offset leaves
// int32 (the loop of any layout then reruns the cloud and reports the error).
using FastConverter = bool (*)(const ros1::PointCloud2View&, const uint32_t[6], double,
                               const FastColumns&, FastResult*);

// The loop compiled for the layout of a cloud (`swap`: big-endian), or null
// when the loop of any layout must run.
FastConverter PickFastConverter(bool swap, const CloudLayout& layout);

}  // namespace tiltcal::decode

#endif  // TILTCAL_STAGES_DECODE_FAST_POINT_CONVERSION_H_
