#ifndef TILTCAL_STAGES_SIMULATE_PEDESTRIANS_H_
#define TILTCAL_STAGES_SIMULATE_PEDESTRIANS_H_

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "stages/simulate/world.h"
#include "tiltcal/proto/simulate_params.pb.h"

namespace tiltcal::simulate {

// One person walking at constant speed along a polyline of waypoints in the
// simulation world w (x, y), from the first waypoint at t = 0.
struct Pedestrian {
  double radius_m = 0.25;
  double height_m = 1.75;  // above the mean ground plane at the person's centre
  double speed_mps = 1.4;
  std::vector<Eigen::Vector2d> waypoints;  // w (x, y), m
  std::vector<double> arrival_s;           // time at each waypoint, s since the first IMU sample
};

// People walking through the scene (SimPedestrianParams), seen by the
// LiDAR: each a gravity-vertical cylinder (as a pillar, side surface only)
// that moves with time. STRAIGHT_LINE: back and forth between two random
// points of the room at least 2 m apart; RANDOM_WAYPOINTS: from one random
// point of the room to the next. Points are drawn uniformly in the room
// (1 m from its walls) from the pedestrian stream of the seed (random.h),
// whatever the track: people cross the vehicle's path and pass through
// boxes and pillars.
class Pedestrians {
 public:
  Pedestrians() = default;
  // Walks covering [0, duration_s] in a room of that half size.
  Pedestrians(const proto::SimPedestrianParams& params, double room_half_size_m,
              double duration_s, uint64_t seed);

  bool empty() const { return people_.empty(); }
  const std::vector<Pedestrian>& people() const { return people_; }

  // Centre (x, y) in w of person i at time t (s since the first IMU sample).
  Eigen::Vector2d Position(int i, double t) const;

  // Nearest person hit by the ray origin + s · direction (unit) at time t
  // with min_range <= s < max_range; false when none.
  bool Cast(const World& world, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
            double t, double min_range, double max_range, RayHit* hit) const;

 private:
  std::vector<Pedestrian> people_;
};

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_PEDESTRIANS_H_
