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
struct LidarModel {
  enum class Kind { kVelodyne, kOuster };
  std::string name;  // "VLP-16", "VLP-32C", "OS1-32"
  Kind kind = Kind::kVelodyne;
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

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_LIDAR_MODEL_H_
