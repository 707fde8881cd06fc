#ifndef TILTCAL_STAGES_SIMULATE_LIDAR_MODEL_H_
#define TILTCAL_STAGES_SIMULATE_LIDAR_MODEL_H_

#include <string>
#include <vector>

namespace tiltcal::simulate {

// Geometry and firing pattern of a spinning LiDAR.
//
// Velodyne (VLP-16, VLP-32C): one firing sequence every 55.296 µs; within a
// sequence laser slot k fires at k * 2.304 µs (the VLP-32C fires two lasers
// per slot). Points are written in firing order; `ring` orders lasers by
// elevation (0 = lowest), as the ros-drivers velodyne_pointcloud driver.
// Ouster (OS1-32): columns at 1 / (rate * columns) s; all beams of a column
// share its time (destaggered cloud); rows are beams with row 0 = highest
// elevation, `ring` = row.
// Both spin clockwise seen from above: the horizontal angle of a firing at
// time t after the sweep start is −2π · rate · t.
// Livox (Avia, Mid-360): a non-repetitive pattern, one point of one line
// every 1 / point_rate_hz s, lines in turn; frames of 1 / scan_rate s
// stamped at their first point (timebase). The direction of a point at
// sensor time t (s, continuous over frames, so the pattern never repeats)
// and line l of L:
//   Mid-360 (kLivoxSpin): azimuth 2π (f_az t + l / L), elevation sweeping
//     [min, max] as el_min + (el_max − el_min) (1 − cos(2π f_el t + 2π l / L)) / 2;
//   Avia (kLivoxRosette): two counter-rotating prisms, a rosette:
//     azimuth   = half_az (cos(2π f1 t + 2π l / L) + cos(2π f2 t)) / 2,
//     elevation = half_el (sin(2π f1 t + 2π l / L) − sin(2π f2 t)) / 2,
//   with f1 / f2 irrational.
struct LivoxPattern {
  bool rosette = false;
  int lines = 0;
  double point_rate_hz = 0.0;  // points of all lines, per second
  double f1_hz = 0.0;          // Mid-360: azimuth turns; Avia: prism 1
  double f2_hz = 0.0;          // Mid-360: elevation sweeps; Avia: prism 2 (negative)
  double min_elevation_rad = 0.0, max_elevation_rad = 0.0;  // Mid-360
  double half_azimuth_rad = 0.0, half_elevation_rad = 0.0;  // Avia
};

struct LidarModel {
  enum class Kind { kVelodyne, kOuster, kLivox };
  std::string name;  // "VLP-16", "VLP-32C", "OS1-32", "Livox Avia", "Livox Mid-360"
  Kind kind = Kind::kVelodyne;
  LivoxPattern livox;  // kLivox only
  // Per laser (firing order index): elevation, rad, and ring number.
  std::vector<double> elevation_rad;
  std::vector<int> ring;
  // Per laser: firing time within a sequence / column, s.
  std::vector<double> firing_offset_s;
  double sequence_period_s = 0.0;  // Velodyne: one firing sequence
  int columns = 0;                 // Ouster: columns per revolution

  int num_lasers() const { return static_cast<int>(elevation_rad.size()); }
};

LidarModel Vlp16Model();
LidarModel Vlp32cModel();
LidarModel Os132Model(int columns);
LidarModel LivoxAviaModel();
LidarModel LivoxMid360Model();

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_LIDAR_MODEL_H_
