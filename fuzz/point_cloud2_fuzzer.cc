// libFuzzer harness: any bytes as a serialized sensor_msgs/PointCloud2,
// decoded and converted to a Scan by the fast and the generic loops, which
// must agree byte for byte, except for the payload of a NaN intensity (the
// generic loop reads values through double, which quiets a signalling NaN).
#include <cstddef>
#include <cstdint>
#include <cmath>
#include <cstdlib>

#include "bag/ros1/messages.h"
#include "stages/decode/point_cloud_conversion.h"
#include "tiltcal/proto/scan.pb.h"

namespace {

// Every NaN intensity replaced by the one quiet NaN.
void CanonicalNans(tiltcal::proto::Scan* scan) {
  for (int i = 0; i < scan->intensity_size(); ++i) {
    if (std::isnan(scan->intensity(i))) scan->set_intensity(i, std::nanf(""));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  tiltcal::ros1::PointCloud2View cloud;
  if (!tiltcal::ros1::DecodePointCloud2(data, size, &cloud).ok()) return 0;
  tiltcal::PointConversionOptions fast, generic;
  fast.min_range_m = generic.min_range_m = 0.5;
  generic.allow_fast_path = false;
  tiltcal::proto::Scan fast_scan, generic_scan;
  const bool fast_ok = tiltcal::ConvertPointCloud2ToScan(cloud, fast, &fast_scan).ok();
  const bool generic_ok = tiltcal::ConvertPointCloud2ToScan(cloud, generic, &generic_scan).ok();
  CanonicalNans(&fast_scan);
  CanonicalNans(&generic_scan);
  if (fast_ok != generic_ok ||
      (fast_ok && fast_scan.SerializeAsString() != generic_scan.SerializeAsString())) {
    std::abort();  // the two loops disagree
  }
  return 0;
}
