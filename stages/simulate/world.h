#ifndef TILTCAL_STAGES_SIMULATE_WORLD_H_
#define TILTCAL_STAGES_SIMULATE_WORLD_H_

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace tiltcal::simulate {

// What a ray hit; values match tiltcal.proto.SurfaceLabel.
enum class Surface : uint8_t { kNone = 0, kGround = 1, kWall = 2, kBox = 3, kPillar = 4 };

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

// The static scene in the simulation world w (z up): the ground plane
// n_w · x = 0 through the origin, an optional square room of vertical walls
// (|x| = half size, |y| = half size, up to wall_height above the local
// ground), boxes and pillars. Ray casting is exact (closed form per
// primitive) with a bounding-circle early-out per obstacle.
class World {
 public:
  World(const Eigen::Vector3d& ground_normal_w, double room_half_size_m, double wall_height_m);

  // Height of the ground surface at (x, y): z with n · (x, y, z) = 0.
  double GroundZ(double x, double y) const;

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
  Eigen::Vector3d normal_;
  double half_size_;
  double wall_height_;
  std::vector<Box> boxes_;
  std::vector<Pillar> pillars_;
  std::vector<Bound> box_bounds_;
};

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_WORLD_H_
