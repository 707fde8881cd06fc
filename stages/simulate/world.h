#ifndef TILTCAL_STAGES_SIMULATE_WORLD_H_
#define TILTCAL_STAGES_SIMULATE_WORLD_H_

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace tiltcal::simulate {

// What a ray hit; values match tiltcal.proto.SurfaceLabel.
enum class Surface : uint8_t {
  kNone = 0,
  kGround = 1,
  kWall = 2,
  kBox = 3,
  kPillar = 4,
  kPerson = 5,
};

// A gravity-vertical, axis-aligned box in w: [min_x, max_x] x [min_y, max_y],
// from far below the ground up to top_z.
struct Box {
  double min_x, max_x, min_y, max_y, top_z;
};
// A gravity-vertical cylinder from far below the ground up to top_z (the top
// cap is not modelled: rays reaching above top_z miss).
struct Pillar {
  double center_x, center_y, radius, top_z;
};

struct RayHit {
  double range = 0.0;  // distance along the unit direction, m
  Surface surface = Surface::kNone;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, facing the ray origin
};

// Side hit of the ray origin + s · direction (unit) with a pillar:
// the entry s with min_range <= s < best below the pillar's top, and the
// outward normal there; false when there is none.
bool CastPillar(const Pillar& pillar, const Eigen::Vector3d& origin,
                const Eigen::Vector3d& direction, double min_range, double best, double* range,
                Eigen::Vector3d* normal);

// The static scene in the simulation world w (z up): the ground plane
// n_w · x = 0 through the origin (optionally rolling about it, see
// SetRollingGround), an optional square room of vertical walls
// (|x| = half size, |y| = half size, up to wall_height above the local
// ground), boxes and pillars. Ray casting is exact (closed form per
// primitive) with a bounding-circle early-out per obstacle.
class World {
 public:
  World(const Eigen::Vector3d& ground_normal_w, double room_half_size_m, double wall_height_m);

  // Height of the mean ground plane at (x, y): z with n · (x, y, z) = 0.
  // Walls, boxes and pillars stand on it.
  double GroundZ(double x, double y) const;

  // Rolling ground (SimFaultParams.rolling_ground_*): the ground surface at
  // height h(u, v) = A sin(2π u / λ + φ_u) sin(2π v / λ + φ_v) above the
  // mean plane along n, (u, v, ·) = C_wp^T x the plane coordinates
  // (n = C_wp e_z). A ray that does not descend towards the mean plane
  // (n · d >= 0) misses it, as it misses the plane; a descending ray hits
  // the first crossing of the surface (marched in steps of λ / 32 along
  // the plane, then refined to 1e-9 m).
  void SetRollingGround(const Eigen::Matrix3d& world_from_plane, double amplitude_m,
                        double wavelength_m, double phase_u_rad, double phase_v_rad);
  // h at the plane coordinates of x_w (0 without rolling ground), m.
  double GroundHeight(const Eigen::Vector3d& x_w) const;
  const Eigen::Vector3d& ground_normal() const { return normal_; }

  void AddBox(const Box& box);
  void AddPillar(const Pillar& pillar);
  const std::vector<Box>& boxes() const { return boxes_; }
  const std::vector<Pillar>& pillars() const { return pillars_; }

  // Nearest hit of the ray origin + s * direction (direction unit) with
  // min_range <= s <= max_range; false when nothing is hit.
  bool Cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double min_range,
            double max_range, RayHit* hit) const;

 private:
  struct Bound {  // bounding circle in (x, y) of an obstacle
    double cx, cy, radius, top_z;
  };
  // The rolling ground's hit with min_range <= s <= best (see above).
  bool CastRollingGround(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double min_range,
                         double best, double* range, Eigen::Vector3d* normal) const;
  // h and its gradient (dh/du, dh/dv) at plane coordinates (u, v).
  double RollingHeight(double u, double v, Eigen::Vector2d* gradient) const;

  Eigen::Vector3d normal_;
  Eigen::Matrix3d plane_from_world_ = Eigen::Matrix3d::Identity();  // C_wp^T
  double rolling_amplitude_m_ = 0.0;
  double rolling_wavenumber_ = 0.0;  // 2π / λ, rad/m
  double rolling_phase_u_ = 0.0, rolling_phase_v_ = 0.0;
  double half_size_;
  double wall_height_;
  std::vector<Box> boxes_;
  std::vector<Pillar> pillars_;
  std::vector<Bound> box_bounds_;
};

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_WORLD_H_
