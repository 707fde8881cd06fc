#ifndef TILTCAL_TESTS_COMMON_REGISTRATION_SYNTHETIC_SCENE_H_
#define TILTCAL_TESTS_COMMON_REGISTRATION_SYNTHETIC_SCENE_H_

// A synthetic "room" for registration tests: a floor z = 0, two walls
// x = 8 and y = -6, and a slanted plane, sampled on grids with optional
// Gaussian noise along each plane's normal. Frame: the map's, m.

#include <random>
#include <vector>

#include <Eigen/Core>

namespace tiltcal::registration::testing {

inline std::vector<Eigen::Vector3d> SyntheticRoom(double spacing_m, double noise_m,
                                                  unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_m);
  std::vector<Eigen::Vector3d> points;
  auto sample = [&](const Eigen::Vector3d& origin, const Eigen::Vector3d& u,
                    const Eigen::Vector3d& v, double extent_u, double extent_v) {
    const Eigen::Vector3d n = u.cross(v).normalized();
    for (double a = 0.0; a <= extent_u; a += spacing_m) {
      for (double b = 0.0; b <= extent_v; b += spacing_m) {
        points.push_back(origin + a * u + b * v + (noise_m > 0.0 ? noise(rng) : 0.0) * n);
      }
    }
  };
  sample({-10, -6, 0}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 18, 14);  // floor
  sample({8, -6, 0}, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 14, 4);     // wall x = 8
  sample({-10, -6, 0}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ(), 18, 4);   // wall y = -6
  sample({-8, 6, 0}, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, -0.5, 1).normalized(), 10, 4);
  return points;
}

}  // namespace tiltcal::registration::testing

#endif  // TILTCAL_TESTS_COMMON_REGISTRATION_SYNTHETIC_SCENE_H_
