#include "stages/report/map_snapshots.h"

#include <algorithm>

#include "stages/report/png_encoder.h"
#include "stages/report/base64.h"
#include "stages/report/map_pcd.h"

namespace tiltcal::report {
namespace {

// The 99th percentile of the non-empty pixels (1 when there are none).
uint32_t Saturation(const DensityImage& image) {
  std::vector<uint32_t> counts;
  for (const uint32_t c : image.counts) {
    if (c > 0) counts.push_back(c);
  }
  if (counts.empty()) return 1;
  const auto k = counts.begin() + static_cast<std::ptrdiff_t>(0.99 * (counts.size() - 1));
  std::nth_element(counts.begin(), k, counts.end());
  return std::max<uint32_t>(1, *k);
}

SnapshotImage Encode(const DensityImage& density, uint32_t saturation) {
  SnapshotImage image;
  image.width = density.width;
  image.height = density.height;
  image.data_uri =
      "data:image/png;base64," + EncodeBase64(EncodePng(ShadeDensity(density, saturation)));
  return image;
}

}  // namespace

Status MakeWallSnapshots(const std::string& map_rig_path, const std::string& map_calibrated_path,
                         const Eigen::Vector3d& up, const proto::WallSnapshotParams& params,
                         WallSnapshots* snapshots) {
  *snapshots = WallSnapshots{};
  std::vector<Eigen::Vector3f> rig, calibrated;
  TILTCAL_RETURN_IF_ERROR(ReadMapPcd(map_calibrated_path, &calibrated));
  TILTCAL_RETURN_IF_ERROR(ReadMapPcd(map_rig_path, &rig));
  const std::optional<WallSlab> slab = FindWall(calibrated, up, params);
  if (!slab) {
    snapshots->note = "no vertical planar surface in the calibrated map to draw";
    return Status::Ok();
  }
  snapshots->slab = *slab;
  snapshots->spread_rig_m = WallSpread(rig, *slab);
  snapshots->spread_calibrated_m = WallSpread(calibrated, *slab);
  const double ppm = params.pixels_per_m();
  for (const WallView view : {WallView::kTop, WallView::kSide}) {
    const DensityImage after = RenderWallView(calibrated, *slab, view, ppm);
    const DensityImage before = RenderWallView(rig, *slab, view, ppm);
    const uint32_t saturation = Saturation(after);
    (view == WallView::kTop ? snapshots->top_calibrated : snapshots->side_calibrated) =
        Encode(after, saturation);
    (view == WallView::kTop ? snapshots->top_rig : snapshots->side_rig) =
        Encode(before, saturation);
  }
  return Status::Ok();
}

}  // namespace tiltcal::report
