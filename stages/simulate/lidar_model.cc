#include "stages/simulate/lidar_model.h"
#include "common/geometry/angles.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace tiltcal::simulate {

namespace {

using geometry::kRadPerDeg;
constexpr double kVelodyneSequenceS = 55.296e-6;
constexpr double kVelodyneSlotS = 2.304e-6;

// Ring numbers: lasers ranked by increasing elevation.
std::vector<int> RingsByElevation(const std::vector<double>& elevation) {
  std::vector<int> order(elevation.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return elevation[a] < elevation[b]; });
  std::vector<int> ring(elevation.size());
  for (size_t r = 0; r < order.size(); ++r) ring[order[r]] = static_cast<int>(r);
  return ring;
}

}  // namespace

LidarModel Vlp16Model() {
  // VLP-16 user manual: laser ids 0..15 at −15, 1, −13, 3, … , −1, 15 deg.
  static const double kElevationDeg[16] = {-15, 1, -13, 3, -11, 5, -9, 7,
                                           -7,  9, -5,  11, -3, 13, -1, 15};
  LidarModel m;
  m.name = "VLP-16";
  m.kind = LidarModel::Kind::kVelodyne;
  for (int i = 0; i < 16; ++i) {
    m.elevation_rad.push_back(kElevationDeg[i] * kRadPerDeg);
    m.firing_offset_s.push_back(i * kVelodyneSlotS);
  }
  m.ring = RingsByElevation(m.elevation_rad);
  m.sequence_period_s = kVelodyneSequenceS;
  return m;
}

LidarModel Vlp32cModel() {
  // VLP-32C user manual: vertical angles of laser ids 0..31 (deg); lasers
  // 2k and 2k+1 fire together in slot k.
  static const double kElevationDeg[32] = {
      -25,    -1,     -1.667, -15.639, -11.31, 0,      -0.667, -8.843,
      -7.254, 0.333,  -0.333, -6.148,  -5.333, 1.333,  0.667,  -4,
      -4.667, 1.667,  1,      -3.667,  -3.333, 3.333,  2.333,  -2.667,
      -3,     7,      4.667,  -2.333,  -2,     15,     10.333, -1.333};
  LidarModel m;
  m.name = "VLP-32C";
  m.kind = LidarModel::Kind::kVelodyne;
  for (int i = 0; i < 32; ++i) {
    m.elevation_rad.push_back(kElevationDeg[i] * kRadPerDeg);
    m.firing_offset_s.push_back((i / 2) * kVelodyneSlotS);
  }
  m.ring = RingsByElevation(m.elevation_rad);
  m.sequence_period_s = kVelodyneSequenceS;
  return m;
}

LidarModel Os132Model(int columns) {
  // OS1-32 (uniform beams): 45 deg vertical field of view, row 0 at +22.5 deg.
  LidarModel m;
  m.name = "OS1-32";
  m.kind = LidarModel::Kind::kOuster;
  for (int i = 0; i < 32; ++i) {
    m.elevation_rad.push_back((22.5 - 45.0 * i / 31.0) * kRadPerDeg);
    m.ring.push_back(i);
    m.firing_offset_s.push_back(0.0);
  }
  m.columns = columns;
  return m;
}

LidarModel LivoxAviaModel() {
  // Avia: 6 lines, 70.4 x 77.2 deg field of view, 240 000 points/s (first return).
  LidarModel m;
  m.name = "Livox Avia";
  m.kind = LidarModel::Kind::kLivox;
  m.livox.rosette = true;
  m.livox.lines = 6;
  m.livox.point_rate_hz = 240000.0;
  m.livox.f1_hz = 97.3;
  m.livox.f2_hz = -97.3 * std::sqrt(2.0) * 0.61;
  m.livox.half_azimuth_rad = 35.2 * kRadPerDeg;
  m.livox.half_elevation_rad = 38.6 * kRadPerDeg;
  return m;
}

LidarModel LivoxMid360Model() {
  // Mid-360: 4 lines, 360 x 59 deg (−7 .. +52 deg), 200 000 points/s.
  LidarModel m;
  m.name = "Livox Mid-360";
  m.kind = LidarModel::Kind::kLivox;
  m.livox.lines = 4;
  m.livox.point_rate_hz = 200000.0;
  m.livox.f1_hz = 10.0 * std::sqrt(1.03);
  m.livox.f2_hz = 1000.0 / std::sqrt(2.0);
  m.livox.min_elevation_rad = -7.0 * kRadPerDeg;
  m.livox.max_elevation_rad = 52.0 * kRadPerDeg;
  return m;
}

}  // namespace tiltcal::simulate
