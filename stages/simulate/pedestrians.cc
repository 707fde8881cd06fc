#include "stages/simulate/pedestrians.h"

#include <algorithm>

#include "stages/simulate/random.h"

namespace tiltcal::simulate {

namespace {

constexpr double kWallMarginM = 1.0;
constexpr double kMinStraightLengthM = 2.0;

Eigen::Vector2d RandomPoint(double half, Rng* rng) {
  const double x = rng->Uniform(-half, half);
  const double y = rng->Uniform(-half, half);
  return Eigen::Vector2d(x, y);
}

}  // namespace

Pedestrians::Pedestrians(const proto::SimPedestrianParams& p, double room_half_size_m,
                         double duration_s, uint64_t seed) {
  Rng rng(seed, kPedestrianStream);
  const double half = room_half_size_m - kWallMarginM;
  const bool straight = p.walk() == proto::SimPedestrianParams::STRAIGHT_LINE;
  for (uint32_t n = 0; n < p.count(); ++n) {
    Pedestrian person;
    person.radius_m = p.radius_m();
    person.height_m = p.height_m();
    person.speed_mps = p.speed_mps();
    const Eigen::Vector2d a = RandomPoint(half, &rng);
    Eigen::Vector2d b = RandomPoint(half, &rng);
    while (straight && (b - a).norm() < kMinStraightLengthM) b = RandomPoint(half, &rng);
    person.waypoints.push_back(a);
    person.arrival_s.push_back(0.0);
    Eigen::Vector2d next = b;
    while (person.arrival_s.back() <= duration_s) {
      const Eigen::Vector2d& last = person.waypoints.back();
      person.arrival_s.push_back(person.arrival_s.back() + (next - last).norm() / person.speed_mps);
      person.waypoints.push_back(next);
      next = straight ? person.waypoints[person.waypoints.size() - 2] : RandomPoint(half, &rng);
    }
    people_.push_back(std::move(person));
  }
}

Eigen::Vector2d Pedestrians::Position(int i, double t) const {
  const Pedestrian& person = people_[static_cast<size_t>(i)];
  const auto& arrival = person.arrival_s;
  if (t <= arrival.front()) return person.waypoints.front();
  if (t >= arrival.back()) return person.waypoints.back();
  const size_t j = static_cast<size_t>(std::upper_bound(arrival.begin(), arrival.end(), t) -
                                       arrival.begin());  // arrival[j-1] <= t < arrival[j]
  const double span = arrival[j] - arrival[j - 1];
  const double f = span > 0.0 ? (t - arrival[j - 1]) / span : 1.0;
  return person.waypoints[j - 1] + f * (person.waypoints[j] - person.waypoints[j - 1]);
}

bool Pedestrians::Cast(const World& world, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                       double t, double min_range, double max_range, RayHit* hit) const {
  double best = max_range;
  bool found = false;
  for (size_t i = 0; i < people_.size(); ++i) {
    const Eigen::Vector2d c = Position(static_cast<int>(i), t);
    const Pillar body{c.x(), c.y(), people_[i].radius_m,
                      world.GroundZ(c.x(), c.y()) + people_[i].height_m};
    double range;
    Eigen::Vector3d normal;
    if (!CastPillar(body, o, d, min_range, best, &range, &normal)) continue;
    best = range;
    found = true;
    hit->range = range;
    hit->surface = Surface::kPerson;
    hit->normal = normal;
  }
  return found;
}

}  // namespace tiltcal::simulate
