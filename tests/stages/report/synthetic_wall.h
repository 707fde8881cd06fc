#ifndef TILTCAL_TESTS_STAGES_REPORT_SYNTHETIC_WALL_H_
#define TILTCAL_TESTS_STAGES_REPORT_SYNTHETIC_WALL_H_

#include <cstring>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace tiltcal::report {

// A synthetic scene in frame a (z up): ground z = -0.5 over 12 x 12 m, a
// wall in the plane x = 5.5 (y in [-5, 5), z in [0.2, 3)) made of one sheet
// per x offset in `offsets`, and a smaller wall y = 4.5 (x in [0, 2)).
inline std::vector<Eigen::Vector3f> SyntheticWallScene(const std::vector<double>& offsets) {
  std::vector<Eigen::Vector3f> points;
  for (double x = -6; x < 6; x += 0.1) {
    for (double y = -6; y < 6; y += 0.1) points.emplace_back(x, y, -0.5f);
  }
  for (const double dx : offsets) {
    for (double y = -5; y < 5; y += 0.02) {
      for (double z = 0.205; z < 3; z += 0.02) points.emplace_back(5.5 + dx, y, z);
    }
  }
  for (double x = 0; x < 2; x += 0.05) {
    for (double z = 0.205; z < 2; z += 0.05) points.emplace_back(x, 4.5, z);
  }
  return points;
}

// The bytes of a map PCD as tiltcal_calibrate writes it (x y z scan).
inline std::string MapPcdBytes(const std::vector<Eigen::Vector3f>& points) {
  std::string out = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z scan\n"
                    "SIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH " +
                    std::to_string(points.size()) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " +
                    std::to_string(points.size()) + "\nDATA binary\n";
  for (const Eigen::Vector3f& p : points) {
    out.append(reinterpret_cast<const char*>(p.data()), 12);
    out.append(4, '\0');
  }
  return out;
}

}  // namespace tiltcal::report

#endif  // TILTCAL_TESTS_STAGES_REPORT_SYNTHETIC_WALL_H_
