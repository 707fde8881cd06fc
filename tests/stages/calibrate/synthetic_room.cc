#include "tests/stages/calibrate/synthetic_room.h"

#include <cmath>
#include <limits>

#include "common/geometry/angles.h"

namespace tiltcal::calibrate::testing {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Eigen::Matrix3d Yaw(double yaw) { return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

}  // namespace

int Scene::NumSurfaces() const {
  return 6 + 6 * static_cast<int>(boxes.size()) + static_cast<int>(cylinders.size());
}

bool Scene::IsCylinder(int id) const { return id >= 6 + 6 * static_cast<int>(boxes.size()); }

Surface Scene::SurfaceInfo(int id) const {
  Surface s;
  if (id < 6) {
    const int axis = id / 2;
    const bool max_side = (id % 2) == 1;
    s.normal = Eigen::Vector3d::Zero();
    s.normal(axis) = max_side ? -1.0 : 1.0;  // into the room
    s.offset = max_side ? room_max(axis) : -room_min(axis);
    return s;
  }
  if (IsCylinder(id)) {
    s.planar = false;
    return s;
  }
  const int b = (id - 6) / 6;
  const int face = (id - 6) % 6;
  const int axis = face / 2;
  const double sign = (face % 2) == 1 ? 1.0 : -1.0;
  const OrientedBox& box = boxes[static_cast<std::size_t>(b)];
  Eigen::Vector3d n_local = Eigen::Vector3d::Zero();
  n_local(axis) = sign;
  s.normal = Yaw(box.yaw_rad) * n_local;
  s.offset = -s.normal.dot(box.centre) - box.half_extent(axis);
  return s;
}

double Scene::DistanceTo(int id, const Eigen::Vector3d& p) const {
  if (IsCylinder(id)) {
    const VerticalCylinder& c = cylinders[static_cast<std::size_t>(id - 6 - 6 * static_cast<int>(boxes.size()))];
    return std::abs((p.head<2>() - c.centre_xy).norm() - c.radius);
  }
  const Surface s = SurfaceInfo(id);
  return std::abs(s.normal.dot(p) + s.offset);
}

bool Scene::OnBoundedSurface(int id, const Eigen::Vector3d& p, double tolerance) const {
  if (IsCylinder(id) || DistanceTo(id, p) > tolerance) return false;
  if (id < 6) return true;
  const int face = (id - 6) % 6;
  if (face == 4) return false;
  const OrientedBox& box = boxes[static_cast<std::size_t>((id - 6) / 6)];
  const Eigen::Vector3d q = Yaw(box.yaw_rad).transpose() * (p - box.centre);
  for (int other = 0; other < 3; ++other) {
    if (other != face / 2 && std::abs(q(other)) > box.half_extent(other) + 0.05) return false;
  }
  return true;
}

int Scene::NearestSurface(const Eigen::Vector3d& p, double* distance) const {
  int best = -1;
  double best_d = kInf;
  auto consider = [&](int id, double d) {
    if (d < best_d) {
      best_d = d;
      best = id;
    }
  };
  for (int id = 0; id < 6; ++id) consider(id, DistanceTo(id, p));
  for (std::size_t b = 0; b < boxes.size(); ++b) {
    const OrientedBox& box = boxes[b];
    const Eigen::Vector3d q = Yaw(box.yaw_rad).transpose() * (p - box.centre);
    for (int face = 0; face < 6; ++face) {
      const int axis = face / 2;
      bool inside = true;
      for (int other = 0; other < 3; ++other) {
        if (other != axis && std::abs(q(other)) > box.half_extent(other) + 0.05) inside = false;
      }
      if (!inside) continue;
      const int id = 6 + 6 * static_cast<int>(b) + face;
      consider(id, DistanceTo(id, p));
    }
  }
  for (std::size_t c = 0; c < cylinders.size(); ++c) {
    const int id = 6 + 6 * static_cast<int>(boxes.size()) + static_cast<int>(c);
    consider(id, DistanceTo(id, p));
  }
  if (distance != nullptr) *distance = best_d;
  return best;
}

Scene MakeDefaultScene() {
  Scene scene;
  scene.room_min = Eigen::Vector3d(-14.8, -6.1, -1.37);
  scene.room_max = Eigen::Vector3d(15.3, 5.85, 3.62);
  scene.boxes.push_back({Eigen::Vector3d(5.1, 3.3, -0.52), Eigen::Vector3d(1.1, 0.65, 0.85), 0.52});
  scene.boxes.push_back({Eigen::Vector3d(-6.2, -3.6, 0.1), Eigen::Vector3d(0.8, 0.9, 1.47), -0.35});
  scene.boxes.push_back({Eigen::Vector3d(10.3, -3.2, -0.3), Eigen::Vector3d(1.3, 0.7, 1.07), 0.0});
  scene.cylinders.push_back({Eigen::Vector2d(2.3, -2.4), 0.12});
  scene.cylinders.push_back({Eigen::Vector2d(-3.1, 2.6), 0.15});
  return scene;
}

Hit CastRay(const Scene& scene, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) {
  Hit hit;
  double best = kInf;
  // Room interior: the exit through the nearest face.
  for (int axis = 0; axis < 3; ++axis) {
    if (dir(axis) > 1e-12) {
      const double t = (scene.room_max(axis) - origin(axis)) / dir(axis);
      if (t > 0.0 && t < best) {
        best = t;
        hit.surface = 2 * axis + 1;
      }
    } else if (dir(axis) < -1e-12) {
      const double t = (scene.room_min(axis) - origin(axis)) / dir(axis);
      if (t > 0.0 && t < best) {
        best = t;
        hit.surface = 2 * axis;
      }
    }
  }
  // Boxes: slab test in the box frame.
  for (std::size_t b = 0; b < scene.boxes.size(); ++b) {
    const OrientedBox& box = scene.boxes[b];
    const Eigen::Matrix3d r = Yaw(box.yaw_rad);
    const Eigen::Vector3d o = r.transpose() * (origin - box.centre);
    const Eigen::Vector3d d = r.transpose() * dir;
    double t_near = -kInf, t_far = kInf;
    int near_face = -1;
    bool miss = false;
    for (int axis = 0; axis < 3 && !miss; ++axis) {
      const double h = box.half_extent(axis);
      if (std::abs(d(axis)) < 1e-12) {
        if (std::abs(o(axis)) > h) miss = true;
        continue;
      }
      double t1 = (-h - o(axis)) / d(axis);
      double t2 = (h - o(axis)) / d(axis);
      int face = 2 * axis;  // entering through -axis face when d > 0
      if (t1 > t2) {
        std::swap(t1, t2);
        face = 2 * axis + 1;
      }
      if (t1 > t_near) {
        t_near = t1;
        near_face = face;
      }
      t_far = std::min(t_far, t2);
    }
    if (miss || t_near > t_far || t_near <= 1e-9 || near_face < 0) continue;
    if (t_near < best) {
      best = t_near;
      hit.surface = 6 + 6 * static_cast<int>(b) + near_face;
    }
  }
  // Cylinders (infinite in z; the room caps them).
  for (std::size_t c = 0; c < scene.cylinders.size(); ++c) {
    const VerticalCylinder& cyl = scene.cylinders[c];
    const Eigen::Vector2d dx = origin.head<2>() - cyl.centre_xy;
    const Eigen::Vector2d d = dir.head<2>();
    const double a = d.squaredNorm();
    if (a < 1e-12) continue;
    const double bq = 2.0 * dx.dot(d);
    const double cq = dx.squaredNorm() - cyl.radius * cyl.radius;
    const double disc = bq * bq - 4.0 * a * cq;
    if (disc < 0.0) continue;
    const double t = (-bq - std::sqrt(disc)) / (2.0 * a);
    if (t > 1e-9 && t < best) {
      best = t;
      hit.surface = 6 + 6 * static_cast<int>(scene.boxes.size()) + static_cast<int>(c);
    }
  }
  hit.range = best;
  return hit;
}

SimulatedScan ScanScene(const Scene& scene, const Eigen::Isometry3d& world_from_lidar,
                        const LidarPattern& pattern, double range_sigma_m, std::mt19937* rng) {
  SimulatedScan scan;
  std::normal_distribution<double> noise(0.0, 1.0);
  const Eigen::Matrix3d r = world_from_lidar.linear();
  const Eigen::Vector3d origin = world_from_lidar.translation();
  scan.points.reserve(static_cast<std::size_t>(pattern.num_beams * pattern.num_columns));
  for (int c = 0; c < pattern.num_columns; ++c) {
    const double azimuth = 2.0 * M_PI * c / pattern.num_columns;
    for (int b = 0; b < pattern.num_beams; ++b) {
      const double elevation = geometry::DegToRad(
          pattern.min_elevation_deg +
          (pattern.max_elevation_deg - pattern.min_elevation_deg) * b / std::max(pattern.num_beams - 1, 1));
      const Eigen::Vector3d dir_l(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                                  std::sin(elevation));
      const Hit hit = CastRay(scene, origin, r * dir_l);
      if (hit.surface < 0 || !(hit.range < pattern.max_range_m)) continue;
      const double range = hit.range + (range_sigma_m > 0.0 ? range_sigma_m * noise(*rng) : 0.0);
      scan.points.push_back((range * dir_l).cast<float>());
      scan.surfaces.push_back(hit.surface);
    }
  }
  return scan;
}

}  // namespace tiltcal::calibrate::testing
