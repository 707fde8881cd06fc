#include "stages/simulate/world.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tiltcal::simulate {

World::World(const Eigen::Vector3d& ground_normal_w, double room_half_size_m,
             double wall_height_m)
    : normal_(ground_normal_w.normalized()),
      half_size_(room_half_size_m),
      wall_height_(wall_height_m) {}

double World::GroundZ(double x, double y) const {
  return -(normal_.x() * x + normal_.y() * y) / normal_.z();
}

void World::SetRollingGround(const Eigen::Matrix3d& world_from_plane, double amplitude_m,
                             double wavelength_m, double phase_u_rad, double phase_v_rad) {
  plane_from_world_ = world_from_plane.transpose();
  rolling_amplitude_m_ = amplitude_m;
  rolling_wavenumber_ = 2.0 * M_PI / wavelength_m;
  rolling_phase_u_ = phase_u_rad;
  rolling_phase_v_ = phase_v_rad;
}

double World::RollingHeight(double u, double v, Eigen::Vector2d* gradient) const {
  const double au = rolling_wavenumber_ * u + rolling_phase_u_;
  const double av = rolling_wavenumber_ * v + rolling_phase_v_;
  const double su = std::sin(au), sv = std::sin(av);
  if (gradient != nullptr) {
    *gradient = rolling_amplitude_m_ * rolling_wavenumber_ *
                Eigen::Vector2d(std::cos(au) * sv, su * std::cos(av));
  }
  return rolling_amplitude_m_ * su * sv;
}

double World::GroundHeight(const Eigen::Vector3d& x_w) const {
  if (rolling_amplitude_m_ <= 0.0) return 0.0;
  const Eigen::Vector3d q = plane_from_world_ * x_w;
  return RollingHeight(q.x(), q.y(), nullptr);
}

bool World::CastRollingGround(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                              double min_range, double best, double* range,
                              Eigen::Vector3d* normal) const {
  // Along the ray, in plane coordinates: q(s) = q_o + s q_d; the ray is
  // above the surface while g(s) = q_z(s) − h(q_x(s), q_y(s)) > 0.
  const Eigen::Vector3d q_o = plane_from_world_ * o, q_d = plane_from_world_ * d;
  if (q_d.z() >= 0.0) return false;
  auto g = [&](double s) {
    return q_o.z() + s * q_d.z() - RollingHeight(q_o.x() + s * q_d.x(), q_o.y() + s * q_d.y(),
                                                 nullptr);
  };
  const double amplitude = rolling_amplitude_m_;
  // The surface lies within |q_z| <= A: march from where the ray enters that
  // slab to where it leaves it (or to `best`).
  double s0 = std::max(0.0, (amplitude - q_o.z()) / q_d.z());
  const double s_end = std::min(best, (-amplitude - q_o.z()) / q_d.z());
  double g0 = g(s0);
  if (g0 <= 0.0) return false;  // the origin is below the surface
  const double horizontal = std::max(q_d.head<2>().norm(), 1e-12);
  const double step = 2.0 * M_PI / rolling_wavenumber_ / 32.0 / horizontal;
  while (s0 < s_end) {
    const double s1 = std::min(s0 + step, s_end);
    const double g1 = g(s1);
    if (g1 <= 0.0) {
      // Illinois false position on [s0, s1], g0 > 0 >= g1.
      double a = s0, b = s1, ga = g0, gb = g1;
      int side = 0;
      double s = b;
      for (int iteration = 0; iteration < 100 && b - a > 1e-9; ++iteration) {
        s = (a * gb - b * ga) / (gb - ga);
        const double gs = g(s);
        if (gs > 0.0) {
          a = s;
          ga = gs;
          if (side == 1) gb *= 0.5;
          side = 1;
        } else {
          b = s;
          gb = gs;
          if (side == -1) ga *= 0.5;
          side = -1;
        }
      }
      if (s < min_range) return false;
      Eigen::Vector2d gradient;
      RollingHeight(q_o.x() + s * q_d.x(), q_o.y() + s * q_d.y(), &gradient);
      *range = s;
      *normal = plane_from_world_.transpose() *
                Eigen::Vector3d(-gradient.x(), -gradient.y(), 1.0).normalized();
      return true;
    }
    s0 = s1;
    g0 = g1;
  }
  return false;
}

void World::AddBox(const Box& box) {
  boxes_.push_back(box);
  const double hx = 0.5 * (box.max_x - box.min_x), hy = 0.5 * (box.max_y - box.min_y);
  box_bounds_.push_back({0.5 * (box.min_x + box.max_x), 0.5 * (box.min_y + box.max_y),
                         std::sqrt(hx * hx + hy * hy), box.top_z});
}

void World::AddPillar(const Pillar& pillar) { pillars_.push_back(pillar); }

namespace {

// Entry parameter of the ray (o, d) in (x, y) into a circle (c, r), or +inf
// when the infinite vertical cylinder is missed or lies behind.
inline double CircleEntry(double ox, double oy, double dx, double dy, double cx, double cy,
                          double r, double* exit) {
  const double px = ox - cx, py = oy - cy;
  const double a = dx * dx + dy * dy;
  if (a < 1e-18) return std::numeric_limits<double>::infinity();
  const double b = px * dx + py * dy;  // half of the linear coefficient
  const double c = px * px + py * py - r * r;
  const double disc = b * b - a * c;
  if (disc < 0.0) return std::numeric_limits<double>::infinity();
  const double sq = std::sqrt(disc);
  *exit = (-b + sq) / a;
  return (-b - sq) / a;
}

// Slab test of the ray (o, d) against the box (from 1e6 m below the ground
// up to its top): the entry parameter and *entry_axis, the axis whose face
// it enters through; *entry_axis stays -1 when the ray misses the box or
// starts inside it.
double BoxEntry(const Box& box, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                int* entry_axis) {
  double t0 = -std::numeric_limits<double>::infinity();
  double t1 = std::numeric_limits<double>::infinity();
  int axis_of_t0 = -1;
  const double lo[3] = {box.min_x, box.min_y, -1e6};
  const double hi[3] = {box.max_x, box.max_y, box.top_z};
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(d[axis]) < 1e-15) {
      if (o[axis] < lo[axis] || o[axis] > hi[axis]) return t0;
      continue;
    }
    double ta = (lo[axis] - o[axis]) / d[axis];
    double tb = (hi[axis] - o[axis]) / d[axis];
    if (ta > tb) std::swap(ta, tb);
    if (ta > t0) {
      t0 = ta;
      axis_of_t0 = axis;
    }
    t1 = std::min(t1, tb);
    if (t0 > t1) return t0;
  }
  *entry_axis = axis_of_t0;
  return t0;
}

}  // namespace

bool CastPillar(const Pillar& pillar, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                double min_range, double best, double* range, Eigen::Vector3d* normal) {
  double exit = 0.0;
  const double s = CircleEntry(o.x(), o.y(), d.x(), d.y(), pillar.center_x, pillar.center_y,
                               pillar.radius, &exit);
  if (!(s < best) || s < min_range) return false;
  const Eigen::Vector3d p = o + s * d;
  if (p.z() > pillar.top_z) return false;
  *range = s;
  *normal =
      Eigen::Vector3d(p.x() - pillar.center_x, p.y() - pillar.center_y, 0.0) / pillar.radius;
  return true;
}

bool World::Cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double min_range,
                 double max_range, RayHit* hit) const {
  double best = max_range;
  Surface surface = Surface::kNone;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();

  // Ground plane n · x = 0 (the sensor is above it, n · o > 0), or the
  // rolling ground about it.
  const double denom = normal_.dot(d);
  if (rolling_amplitude_m_ > 0.0) {
    double s;
    Eigen::Vector3d n;
    if (CastRollingGround(o, d, min_range, best, &s, &n)) {
      best = s;
      surface = Surface::kGround;
      normal = n;
    }
  } else if (denom < 0.0) {
    const double s = -normal_.dot(o) / denom;
    if (s >= min_range && s <= best) {
      best = s;
      surface = Surface::kGround;
      normal = normal_;
    }
  }

  // Room walls (from inside): planes x = ±h, y = ±h, up to wall_height above
  // the local ground.
  if (wall_height_ > 0.0) {
    for (int axis = 0; axis < 2; ++axis) {
      const double da = d[axis];
      if (std::abs(da) < 1e-12) continue;
      const double wall = da > 0.0 ? half_size_ : -half_size_;
      const double s = (wall - o[axis]) / da;
      if (s < min_range || s > best) continue;
      const Eigen::Vector3d p = o + s * d;
      const int other = 1 - axis;
      if (std::abs(p[other]) > half_size_) continue;
      if (p.z() > GroundZ(p.x(), p.y()) + wall_height_) continue;
      best = s;
      surface = Surface::kWall;
      normal = Eigen::Vector3d::Zero();
      normal[axis] = da > 0.0 ? -1.0 : 1.0;
    }
  }

  // Boxes: early-out on the bounding circle, then the slab test.
  for (size_t i = 0; i < boxes_.size(); ++i) {
    const Bound& bound = box_bounds_[i];
    double exit = 0.0;
    const double entry = CircleEntry(o.x(), o.y(), d.x(), d.y(), bound.cx, bound.cy,
                                     bound.radius, &exit);
    if (!(entry < best) || exit < min_range) continue;
    int entry_axis = -1;
    const double t0 = BoxEntry(boxes_[i], o, d, &entry_axis);
    if (entry_axis < 0 || t0 < min_range || t0 > best) continue;
    best = t0;
    surface = Surface::kBox;
    normal = Eigen::Vector3d::Zero();
    normal[entry_axis] = d[entry_axis] > 0.0 ? -1.0 : 1.0;
  }

  // Pillars: vertical cylinders, side surface only.
  for (const Pillar& pillar : pillars_) {
    double s;
    Eigen::Vector3d n;
    if (!CastPillar(pillar, o, d, min_range, best, &s, &n)) continue;
    best = s;
    surface = Surface::kPillar;
    normal = n;
  }

  if (surface == Surface::kNone) return false;
  hit->range = best;
  hit->surface = surface;
  hit->normal = normal;
  return true;
}

}  // namespace tiltcal::simulate
