#ifndef TILTCAL_STAGES_REPORT_WALL_SNAPSHOT_H_
#define TILTCAL_STAGES_REPORT_WALL_SNAPSHOT_H_

// Before/after snapshots of one wall of a map (the report page's evidence
// that the calibrated map is sharper): the wall is found in the calibrated
// map and the same slab around it is drawn for both maps, from above (top
// view: along the wall x across it, so a doubled or thick wall shows as a
// wide band) and looking along the wall (side view: across x up, its
// thickness and lean). Frame a of the maps (map_export.h), m.
//
// The wall: the points are binned into cubic cells (WallSnapshotParams.cell_m);
// a cell with enough points whose scatter has l3 / l2 < max_cell_planarity
// and whose normal n (eigenvector of l3) has |n . up| < max_normal_up is a
// wall cell; neighbouring wall cells (26-neighbourhood) join when their
// normals are within max_normal_angle_deg and each centroid is within
// max_plane_distance_m of the other's plane. The cluster with the most
// points is the wall; its plane is fitted to all of its points.

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "stages/report/png_encoder.h"
#include "tiltcal/proto/report_params.pb.h"

namespace tiltcal::report {

// The slab around the wall: an orthonormal frame (along, across, up) at
// `center`, frame a. along and across are horizontal (across = the wall's
// normal without its vertical part), along = across x up, up = along x
// across (the map's vertical).
struct WallSlab {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // the wall's centroid, m
  Eigen::Vector3d along = Eigen::Vector3d::UnitX();
  Eigen::Vector3d across = Eigen::Vector3d::UnitY();
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  double length_m = 0.0;  // along, centred
  double depth_m = 0.0;   // across, centred
  double bottom_m = 0.0;  // along up, from center
  double top_m = 0.0;
  int cells = 0;          // cells of the wall cluster
  int64_t points = 0;     // points in them
};

// The largest vertical planar cluster of `points`; `up` is the map's
// vertical (unit, frame a: -g_a / |g_a|). nullopt when no cell qualifies.
std::optional<WallSlab> FindWall(const std::vector<Eigen::Vector3f>& points,
                                 const Eigen::Vector3d& up,
                                 const proto::WallSnapshotParams& params);

enum class WallView {
  kTop,   // columns: along (left to right), rows: across (+across at the top)
  kSide,  // columns: across (left to right), rows: up (top at the top)
};

// Points per pixel of the slab seen in `view`, pixels_per_m on both axes.
struct DensityImage {
  int width = 0;
  int height = 0;
  std::vector<uint32_t> counts;  // row-major, row 0 at the top
};

DensityImage RenderWallView(const std::vector<Eigen::Vector3f>& points, const WallSlab& slab,
                            WallView view, double pixels_per_m);

// How thick the wall is in the slab: the robust σ of the points' distance
// across it, 1.4826 median |b − median(b)| (m), over the points in the
// slab; 0 when it holds none. A wrong extrinsic smears or doubles the wall
// and raises it.
double WallSpread(const std::vector<Eigen::Vector3f>& points, const WallSlab& slab);

// Dark on white: 255 (1 - log(1 + c) / log(1 + saturation)), clamped at 0
// (use the same saturation for images to be compared).
GrayImage ShadeDensity(const DensityImage& density, uint32_t saturation);

}  // namespace tiltcal::report

#endif  // TILTCAL_STAGES_REPORT_WALL_SNAPSHOT_H_
