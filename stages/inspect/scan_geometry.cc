#include "stages/inspect/scan_geometry.h"

#include <cmath>

#include <Eigen/Geometry>

#include "common/geometry/angles.h"
#include "common/geometry/plane_fit.h"

namespace tiltcal::inspect {
namespace {

// Eigen::Quaterniond::FromTwoVectors(up, +z) as a rotation matrix, the same
// arithmetic, except that when up is -z it turns half about x instead of
// about an axis from a JacobiSVD, whose instantiation was most of this
// file's compile time (the heights and horizontal ranges measured below do
// not depend on the axis of a half turn).
Eigen::Matrix3d Levelling(const Eigen::Vector3d& up) {
  const Eigen::Vector3d v0 = up.normalized();
  const double c = v0.z();
  if (c < -1.0 + 1e-12) return Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  const double s = std::sqrt((1.0 + c) * 2.0);
  const double inverse_s = 1.0 / s;
  Eigen::Quaterniond q;
  q.vec() = v0.cross(Eigen::Vector3d::UnitZ()) * inverse_s;
  q.w() = s * 0.5;
  return q.toRotationMatrix();
}

}  // namespace

ScanGeometry MeasureScanGeometry(const std::vector<float>& x, const std::vector<float>& y,
                                 const std::vector<float>& z, const Eigen::Vector3d& up_in_lidar,
                                 const ScanGeometryOptions& options) {
  ScanGeometry g;
  g.num_points = x.size();
  if (x.empty()) return g;
  // Rotation to a frame whose z is up.
  const Eigen::Matrix3f level = Levelling(up_in_lidar.normalized()).cast<float>();
  std::vector<float> gx, gy, gz;
  size_t num_structure = 0;
  const float ground_range2 =
      static_cast<float>(options.ground_max_range_m * options.ground_max_range_m);
  const float structure_range2 =
      static_cast<float>(options.structure_max_range_m * options.structure_max_range_m);
  for (size_t i = 0; i < x.size(); ++i) {
    const Eigen::Vector3f p = level * Eigen::Vector3f(x[i], y[i], z[i]);
    const float range2 = p.x() * p.x() + p.y() * p.y();
    if (p.z() < -options.ground_min_depth_m && range2 <= ground_range2) {
      gx.push_back(p.x());
      gy.push_back(p.y());
      gz.push_back(p.z());
    }
    if (p.z() > options.structure_min_height_m && range2 <= structure_range2) ++num_structure;
  }
  g.structure_fraction = static_cast<double>(num_structure) / static_cast<double>(x.size());
  if (gx.size() < 10) return g;
  geometry::RobustPlaneOptions fit_options;
  fit_options.inlier_distance_m = options.ground_inlier_distance_m;
  fit_options.max_iterations = options.ground_fit_max_iterations;
  std::vector<uint8_t> inlier;
  const geometry::PlaneFit plane =
      geometry::FitPlaneRobust(gx.data(), gy.data(), gz.data(), gx.size(), fit_options, &inlier);
  if (!plane.ok) return g;
  const size_t num_on_plane =
      geometry::CountWithinBand(gx.data(), gy.data(), gz.data(), gx.size(), 1, plane.normal,
                                plane.offset, options.ground_inlier_distance_m);
  g.ground_fraction = static_cast<double>(num_on_plane) / static_cast<double>(x.size());
  g.ground_tilt_deg = geometry::RadToDeg(std::acos(std::min(1.0, std::abs(plane.normal.z()))));
  g.has_ground = g.ground_tilt_deg <= options.ground_max_tilt_deg &&
                 g.ground_fraction >= options.min_ground_fraction;
  return g;
}

}  // namespace tiltcal::inspect
