#include "stages/calibrate/problem/surfel_map.h"

#include <cmath>
#include <map>
#include <random>
#include <string>
#include <set>
#include <algorithm>
#include <cstdio>

#include <gtest/gtest.h>

#include "common/geometry/angles.h"
#include "stages/calibrate/problem/point_priority.h"
#include "tests/stages/calibrate/calibrate_params_text.h"
#include "tests/stages/calibrate/synthetic_room.h"

namespace tiltcal::calibrate {
namespace {

using testing::LidarPattern;
using testing::MakeDefaultScene;
using testing::Scene;
using testing::ScanScene;
using testing::SimulatedScan;

using geometry::kRadPerDeg;

double NormalAngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  // Sign-free: a plane's normal is defined up to sign.
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b))) / kRadPerDeg;
}

// LiDAR poses in the scene frame w along the room, with yaw and some tilt.
std::vector<Eigen::Isometry3d> MapPoses() {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 20; ++i) {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.linear() = (Eigen::AngleAxisd(0.3 * i, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(0.04 * std::sin(i), Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(0.03 * std::cos(i), Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    t.translation() = Eigen::Vector3d(-9.0 + 0.95 * i, 0.5 * std::sin(0.7 * i), 0.1 + 0.02 * std::cos(i));
    poses.push_back(t);
  }
  return poses;
}

// Map frame a is the scene frame shifted and rotated, to exercise the
// transform (a_from_lidar = a_from_w * w_from_lidar).
Eigen::Isometry3d AFromW() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.1, 0.2, 1.0).normalized()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(0.37, -1.21, 0.44);
  return t;
}

// The surfel map of a room: 0.5 m voxels, surfels at most 4 cm thick with a
// normal known to 0.005 rad (0.2865 deg), sample inliers within 5 cm and at
// least 80 % of them (the program's defaults are for outdoor sequences).
proto::SurfelMapParams RoomMapParams() {
  return tiltcal::testing::DefaultCalibrateParamsWith(R"pb(
           map {
             voxel_m: 0.5
             max_thickness_m: 0.04
             max_normal_sigma_deg: 0.28647889756541161
             inlier_distance_m: 0.05
             min_inlier_fraction: 0.8
           })pb")
      .map();
}

// Association with a 5 cm plane gate and, unless given, no per-surfel cap
// in effect.
proto::AssociationParams RoomAssociation(int max_points_per_surfel = 1000000) {
  return tiltcal::testing::DefaultCalibrateParamsWith(
             "association { max_distance_m: 0.05 max_points_per_surfel_per_scan: " +
             std::to_string(max_points_per_surfel) + " }")
      .association();
}

class SurfelMapRoomTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = MakeDefaultScene();
    std::mt19937 rng(21);
    const LidarPattern pattern;  // 16 x 1800
    map_ = std::make_unique<SurfelMap>(options_);
    for (const Eigen::Isometry3d& w_from_l : MapPoses()) {
      const SimulatedScan scan = ScanScene(scene_, w_from_l, pattern, 0.01, &rng);
      map_->AddPoints(a_from_w_ * w_from_l, scan.points);
    }
    summary_ = map_->ExtractSurfels();
  }

  // A new scan (900 columns, 1 cm noise) from a pose between the map poses.
  static Eigen::Isometry3d QueryPose() {
    Eigen::Isometry3d w_from_l = Eigen::Isometry3d::Identity();
    w_from_l.linear() = Eigen::AngleAxisd(0.9, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    w_from_l.translation() = Eigen::Vector3d(-2.0, 0.3, 0.05);
    return w_from_l;
  }
  SimulatedScan QueryScan(unsigned seed) const {
    std::mt19937 rng(seed);
    LidarPattern pattern;
    pattern.num_columns = 900;
    return ScanScene(scene_, QueryPose(), pattern, 0.01, &rng);
  }

  Scene scene_;
  proto::SurfelMapParams options_ = RoomMapParams();
  Eigen::Isometry3d a_from_w_ = AFromW();
  std::unique_ptr<SurfelMap> map_;
  SurfelExtractionSummary summary_;
};

TEST_F(SurfelMapRoomTest, SurfelsLieOnTheTruePlanesWithMatchingNormals) {
  ASSERT_GT(summary_.num_surfels, 200) << summary_.num_voxels << " voxels";
  const Eigen::Isometry3d w_from_a = a_from_w_.inverse();
  std::set<int> planes_found;
  std::map<int, Eigen::Vector3d> plane_normal_sum;
  std::vector<double> errors_deg;
  double worst_normal_deg = 0.0;
  double worst_offset_m = 0.0;
  for (const Surfel& s : map_->surfels()) {
    const Eigen::Vector3d centroid_w = w_from_a * s.centroid;
    const Eigen::Vector3d normal_w = w_from_a.linear() * s.normal;
    // The planar surface the surfel lies on: centroid within 2 cm of it (and
    // inside the face for a box), best normal agreement.
    int id = -1;
    double best_angle = 1e9;
    for (int candidate = 0; candidate < scene_.NumSurfaces(); ++candidate) {
      if (!scene_.OnBoundedSurface(candidate, centroid_w, 0.02)) continue;
      const double angle = NormalAngleDeg(normal_w, scene_.SurfaceInfo(candidate).normal);
      if (angle < best_angle) {
        best_angle = angle;
        id = candidate;
      }
    }
    ASSERT_GE(id, 0) << "surfel off every plane at " << centroid_w.transpose() << " n " << normal_w.transpose()
                     << " ev " << s.eigenvalues_m2.transpose() << " count " << s.num_points;
    const testing::Surface truth = scene_.SurfaceInfo(id);
    worst_normal_deg = std::max(worst_normal_deg, best_angle);
    errors_deg.push_back(best_angle);
    EXPECT_LT(best_angle, 3.0) << "surface " << id << " at " << centroid_w.transpose() << " sigma "
                               << s.normal_sigma_rad / kRadPerDeg << " deg, n " << s.num_points;
    // Plane equation in a is consistent: n^T c + d = 0 and |n| = 1.
    EXPECT_NEAR(s.normal.norm(), 1.0, 1e-12);
    worst_offset_m = std::max(worst_offset_m, std::abs(s.normal.dot(s.centroid) + s.offset_m));
    // Normals face the sensors, i.e. into the room / out of the boxes.
    EXPECT_GT(normal_w.dot(truth.normal), 0.0) << "surface " << id;
    planes_found.insert(id);
    // Count-weighted sum of the surfel normals of each plane (signs aligned).
    plane_normal_sum.try_emplace(id, Eigen::Vector3d::Zero()).first->second += s.num_points * (normal_w.dot(truth.normal) >= 0 ? normal_w : -normal_w);
  }
  double worst_plane_deg = 0.0;
  for (const auto& [id, sum] : plane_normal_sum) {
    const double angle = NormalAngleDeg(sum.normalized(), scene_.SurfaceInfo(id).normal);
    worst_plane_deg = std::max(worst_plane_deg, angle);
    // Room planes within 0.5 deg; box faces, seen only at grazing angles from
    // one side, carry the along-ray noise bias (up to ~1 deg at 1 cm noise).
    EXPECT_LT(angle, id < 6 ? 0.5 : 1.2) << "plane " << id;
  }
  std::sort(errors_deg.begin(), errors_deg.end());
  const double median_deg = errors_deg[errors_deg.size() / 2];
  const double p95_deg = errors_deg[errors_deg.size() * 95 / 100];
  std::printf(
      "surfel map: %d voxels, %d surfels (%d refitted) on %zu planes; surfel normal error median %.3f, 95%% %.3f, "
      "max %.3f deg; worst per-plane mean normal %.3f deg\n",
      summary_.num_voxels, summary_.num_surfels, summary_.refitted, plane_normal_sum.size(), median_deg, p95_deg,
      worst_normal_deg, worst_plane_deg);
  // The bulk is accurate. Single surfels of this sparse 20-scan map can be
  // tilted by a few degrees: range noise acts along the rays, so on a narrow
  // patch seen at a grazing angle the PCA plane is biased (~sigma^2; 1 cm
  // noise gives up to ~2.5 deg, 3 mm ~0.3 deg), and the foot of a
  // neighbouring plane can survive the outlier check.
  EXPECT_LT(median_deg, 0.25);
  EXPECT_LT(p95_deg, 0.75);
  EXPECT_LT(worst_offset_m, 1e-9);
  // All six room faces (floor, ceiling, four walls) and faces of every box.
  for (int id = 0; id < 6; ++id) EXPECT_TRUE(planes_found.count(id)) << "room face " << id;
  for (int b = 0; b < 3; ++b) {
    int faces = 0;
    for (int f = 0; f < 6; ++f) faces += static_cast<int>(planes_found.count(6 + 6 * b + f));
    EXPECT_GE(faces, 1) << "box " << b;
  }
  // Corners, edges and cylinders were rejected somewhere.
  EXPECT_GT(summary_.rejected_not_flat + summary_.rejected_line_like + summary_.rejected_too_thick +
                summary_.rejected_outliers,
            20);
  EXPECT_EQ(summary_.num_voxels, summary_.num_surfels + summary_.rejected_too_few_points +
                                     summary_.rejected_not_flat + summary_.rejected_line_like +
                                     summary_.rejected_too_thick + summary_.rejected_outliers +
                                     summary_.rejected_uncertain_normal);
}

TEST_F(SurfelMapRoomTest, AssociationReturnsTheSurfelOfTheTrueSurface) {
  const Eigen::Isometry3d w_from_l = QueryPose();
  const SimulatedScan scan = QueryScan(22);
  std::vector<Eigen::Vector3d> points_a;
  for (const Eigen::Vector3f& p : scan.points) points_a.push_back(a_from_w_ * w_from_l * p.cast<double>());

  const proto::AssociationParams options = RoomAssociation();
  const std::vector<SurfelAssociation> all = map_->Associate(points_a, options);
  int planar_points = 0;
  for (const int id : scan.surfaces) planar_points += scene_.IsCylinder(id) ? 0 : 1;
  ASSERT_GT(all.size(), 0.4 * planar_points) << all.size() << " of " << planar_points;
  const Eigen::Isometry3d w_from_a = a_from_w_.inverse();
  int wrong = 0;
  for (const SurfelAssociation& a : all) {
    const int id = scan.surfaces[static_cast<std::size_t>(a.point_index)];
    const Surfel& s = map_->surfels()[static_cast<std::size_t>(a.surfel_index)];
    EXPECT_LE(std::abs(a.distance_m), options.max_distance_m());
    EXPECT_NEAR(a.distance_m, s.normal.dot(points_a[static_cast<std::size_t>(a.point_index)]) + s.offset_m, 1e-12);
    // The surfel describes the plane the point was measured on.
    // Wrong: a cylinder point, or a surfel not on the point's plane.
    const Eigen::Vector3d normal_w = w_from_a.linear() * s.normal;
    if (!scene_.OnBoundedSurface(id, w_from_a * s.centroid, 0.02) ||
        NormalAngleDeg(normal_w, scene_.SurfaceInfo(id).normal) > 3.0) {
      ++wrong;
    }
  }
  std::printf("association: %zu of %d planar points, %d wrong\n", all.size(), planar_points, wrong);
  // Only points right at plane intersections may pick the neighbouring plane's surfel.
  EXPECT_LT(wrong, 0.01 * static_cast<double>(all.size())) << wrong << " of " << all.size();

  // Deterministic subsampling: every 4th point (as the association stage
  // queries them) and a per-surfel cap.
  const proto::AssociationParams sub = RoomAssociation(3);
  std::vector<Eigen::Vector3d> every_fourth;
  for (std::size_t i = 0; i < points_a.size(); i += 4) every_fourth.push_back(points_a[i]);
  const std::vector<SurfelAssociation> a1 = map_->Associate(every_fourth, sub);
  const std::vector<SurfelAssociation> a2 = map_->Associate(every_fourth, sub);
  ASSERT_EQ(a1.size(), a2.size());
  std::map<int, int> per_surfel;
  for (std::size_t i = 0; i < a1.size(); ++i) {
    EXPECT_EQ(a1[i].point_index, a2[i].point_index);
    EXPECT_EQ(a1[i].surfel_index, a2[i].surfel_index);
    EXPECT_LT(a1[i].point_index, static_cast<int>(every_fourth.size()));
    if (i > 0) {
      EXPECT_LT(a1[i - 1].point_index, a1[i].point_index);
    }
    ++per_surfel[a1[i].surfel_index];
  }
  for (const auto& [surfel, count] : per_surfel) EXPECT_LE(count, 3);
  EXPECT_LT(a1.size(), all.size() / 4 + 1);
  EXPECT_GT(a1.size(), 0u);

  // A wrong pose (0.3 m off along the room) associates far fewer points.
  std::vector<Eigen::Vector3d> shifted = points_a;
  for (Eigen::Vector3d& p : shifted) p += a_from_w_.linear() * Eigen::Vector3d(0.3, 0.2, 0.15);
  EXPECT_LT(map_->Associate(shifted, options).size(), all.size() / 3);
}

TEST_F(SurfelMapRoomTest, FixedPrioritiesKeepThePicksOfSurfelsWhoseCandidatesDidNotChange) {
  const Eigen::Isometry3d w_from_l = QueryPose();
  const SimulatedScan scan = QueryScan(23);
  std::vector<Eigen::Vector3d> points_a;
  std::vector<uint64_t> priorities;
  for (std::size_t i = 0; i < scan.points.size(); i += 4) {
    points_a.push_back(a_from_w_ * w_from_l * scan.points[i].cast<double>());
    priorities.push_back(PointPriority(7, i));
  }
  const proto::AssociationParams cap2 = RoomAssociation(2);
  const std::vector<SurfelAssociation> before = map_->Associate(points_a, cap2, priorities);
  ASSERT_GT(before.size(), 50u);

  // The picks of a surfel are its candidates of lowest priority.
  const std::vector<SurfelAssociation> all = map_->Associate(points_a, RoomAssociation());
  std::map<int, std::vector<uint64_t>> candidate_priorities;
  for (const SurfelAssociation& a : all) {
    candidate_priorities[a.surfel_index].push_back(priorities[static_cast<std::size_t>(a.point_index)]);
  }
  for (auto& [surfel, p] : candidate_priorities) std::sort(p.begin(), p.end());
  std::map<int, std::vector<uint64_t>> picked;
  for (const SurfelAssociation& a : before) {
    picked[a.surfel_index].push_back(priorities[static_cast<std::size_t>(a.point_index)]);
  }
  for (auto& [surfel, p] : picked) {
    std::sort(p.begin(), p.end());
    const std::vector<uint64_t>& c = candidate_priorities.at(surfel);
    EXPECT_EQ(p, std::vector<uint64_t>(c.begin(), c.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(2, c.size()))));
  }

  // The first tenth of the query points moves off the map (a changed map or
  // pose): every surfel none of them was a candidate of keeps its picks.
  std::vector<Eigen::Vector3d> moved = points_a;
  std::set<int> touched;
  for (const SurfelAssociation& a : all) {
    if (a.point_index < static_cast<int>(points_a.size() / 10)) touched.insert(a.surfel_index);
  }
  for (std::size_t i = 0; i < points_a.size() / 10; ++i) moved[i] += Eigen::Vector3d(0.0, 0.0, 50.0);
  const std::vector<SurfelAssociation> after = map_->Associate(moved, cap2, priorities);
  std::set<std::pair<int, int>> before_kept, after_kept;
  for (const SurfelAssociation& a : before) {
    if (!touched.count(a.surfel_index)) before_kept.insert({a.point_index, a.surfel_index});
  }
  for (const SurfelAssociation& a : after) {
    if (!touched.count(a.surfel_index)) after_kept.insert({a.point_index, a.surfel_index});
  }
  ASSERT_GT(before_kept.size(), 20u);
  EXPECT_EQ(before_kept, after_kept);
  EXPECT_TRUE(std::is_sorted(after.begin(), after.end(), [](const SurfelAssociation& a, const SurfelAssociation& b) {
    return a.point_index < b.point_index;
  }));
}

TEST(PointPriorityTest, IsFixedAndSpreadsTheLowestPicksOverTheScan) {
  EXPECT_EQ(PointPriority(3, 17), PointPriority(3, 17));
  EXPECT_NE(PointPriority(3, 17), PointPriority(17, 3));
  EXPECT_NE(PointPriority(0, 1), PointPriority(1, 0));
  // The 64 lowest of 4000 points of one scan: spread like a uniform sample
  // (mean index 2000 +- 3 standard errors of 1155 / sqrt(64)), all distinct.
  std::vector<std::pair<uint64_t, int>> ranked;
  for (int j = 0; j < 4000; ++j) ranked.push_back({PointPriority(5, j), j});
  std::sort(ranked.begin(), ranked.end());
  std::set<uint64_t> distinct;
  double mean_index = 0.0;
  for (int i = 0; i < 64; ++i) mean_index += ranked[i].second / 64.0;
  for (const auto& r : ranked) distinct.insert(r.first);
  EXPECT_EQ(distinct.size(), ranked.size());
  EXPECT_NEAR(mean_index, 2000.0, 3.0 * 1155.0 / 8.0);
}

// Controlled voxels: each of these point sets fills exactly one voxel.
std::vector<Eigen::Vector3d> GridOnPlane(const Eigen::Vector3d& origin, const Eigen::Vector3d& u,
                                         const Eigen::Vector3d& v, int n, double size) {
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) out.push_back(origin + (size * (i + 0.5) / n) * u + (size * (j + 0.5) / n) * v);
  }
  return out;
}

TEST(SurfelMapTest, GateRejectsCornersCurvesLinesAndThickClouds) {
  const proto::SurfelMapParams options = RoomMapParams();
  SurfelMap map(options);
  const Eigen::Vector3d ex = Eigen::Vector3d::UnitX(), ey = Eigen::Vector3d::UnitY(), ez = Eigen::Vector3d::UnitZ();
  // Voxel (0,0,0): a tilted plane -> accepted, exact normal.
  const Eigen::Vector3d n_tilted = Eigen::Vector3d(0.2, -0.1, 1.0).normalized();
  const Eigen::Vector3d u = n_tilted.cross(ex).normalized(), v = n_tilted.cross(u);
  std::vector<Eigen::Vector3d> plane;
  for (const Eigen::Vector3d& p : GridOnPlane(Eigen::Vector3d::Zero(), u, v, 10, 0.3)) {
    plane.push_back(Eigen::Vector3d(0.25, 0.25, 0.25) + p - 0.15 * (u + v));
  }
  map.AddPointsInWorld(plane);
  // Voxel (2,0,0): a corner (two perpendicular planes).
  std::vector<Eigen::Vector3d> corner = GridOnPlane(Eigen::Vector3d(1.02, 0.02, 0.02), ex, ey, 8, 0.46);
  for (const Eigen::Vector3d& p : GridOnPlane(Eigen::Vector3d(1.02, 0.02, 0.02), ey, ez, 8, 0.46)) corner.push_back(p);
  map.AddPointsInWorld(corner);
  // Voxel (4,0,0): a cylinder of radius 0.15 (half of it visible).
  std::vector<Eigen::Vector3d> cylinder;
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 10; ++j) {
      const double angle = M_PI * i / 19.0;
      cylinder.push_back(Eigen::Vector3d(2.25 + 0.15 * std::cos(angle), 0.25 + 0.15 * std::sin(angle), 0.02 + 0.046 * j));
    }
  }
  map.AddPointsInWorld(cylinder);
  // Voxel (6,0,0): a line (one scan ring).
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 30; ++i) line.push_back(Eigen::Vector3d(3.02 + 0.015 * i, 0.25, 0.25));
  map.AddPointsInWorld(line);
  // Voxel (8,0,0): a thick slab (sigma 8 cm) -- flat-ish, but too thick for 5 cm.
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 0.08);
  std::vector<Eigen::Vector3d> thick;
  for (const Eigen::Vector3d& p : GridOnPlane(Eigen::Vector3d(4.0, 0.0, 0.25), ex, ey, 10, 0.5)) {
    thick.push_back(Eigen::Vector3d(p.x(), p.y(), std::clamp(p.z() + n(rng), 0.01, 0.49)));
  }
  proto::SurfelMapParams loose = options;
  loose.set_max_planarity(1.0);  // isolate the thickness gate on this voxel
  loose.set_sample_points(0);    // no outlier check
  loose.set_max_normal_sigma_deg(geometry::RadToDeg(1.0));
  map.AddPointsInWorld(thick);
  // Voxel (10,0,0): too few points.
  map.AddPointsInWorld({Eigen::Vector3d(5.1, 0.1, 0.1), Eigen::Vector3d(5.2, 0.3, 0.1), Eigen::Vector3d(5.3, 0.1, 0.2)});

  // Voxel (12,0,0): a floor patch with a few points of a wall at its edge ->
  // accepted after refitting on the inliers, with the floor's normal.
  std::vector<Eigen::Vector3d> floor = GridOnPlane(Eigen::Vector3d(6.02, 0.02, 0.1), ex, ey, 10, 0.46);
  for (int i = 0; i < 6; ++i) floor.push_back(Eigen::Vector3d(6.48, 0.1 + 0.05 * i, 0.3 + 0.02 * i));
  map.AddPointsInWorld(floor);

  const SurfelExtractionSummary summary = map.ExtractSurfels();
  EXPECT_EQ(summary.num_voxels, 7);
  ASSERT_EQ(summary.num_surfels, 2);
  EXPECT_EQ(summary.refitted, 1);
  EXPECT_EQ(summary.rejected_too_few_points, 1);
  EXPECT_EQ(summary.rejected_line_like, 1);
  EXPECT_EQ(summary.rejected_not_flat + summary.rejected_too_thick + summary.rejected_outliers +
                summary.rejected_uncertain_normal,
            3);
  EXPECT_LT(NormalAngleDeg(map.surfels()[1].normal, ez), 1e-6);
  EXPECT_NEAR(map.surfels()[1].offset_m, -0.1 * map.surfels()[1].normal.z(), 1e-6);  // float sample
  EXPECT_EQ(map.surfels()[1].num_points, 106);
  const Surfel& s = map.surfels()[0];
  EXPECT_EQ(s.voxel, Eigen::Vector3i(0, 0, 0));
  EXPECT_LT(NormalAngleDeg(s.normal, n_tilted), 1e-6);
  EXPECT_NEAR(s.normal.dot(Eigen::Vector3d(0.25, 0.25, 0.25)) + s.offset_m, 0.0, 1e-12);
  EXPECT_EQ(s.num_points, 100);
  EXPECT_EQ(map.SurfelIndexAt(Eigen::Vector3d(0.1, 0.4, 0.3)), 0);
  EXPECT_EQ(map.SurfelIndexAt(Eigen::Vector3d(1.1, 0.1, 0.1)), -1);
  EXPECT_EQ(map.SurfelIndexAt(Eigen::Vector3d(-0.1, 0.1, 0.1)), -1);
  EXPECT_EQ(map.VoxelOf(Eigen::Vector3d(-0.1, 0.6, 1.0)), Eigen::Vector3i(-1, 1, 2));

  // The thick slab alone: flat by the ratio gate when it is relaxed, then
  // caught by the thickness gate.
  SurfelMap thick_map(loose);
  thick_map.AddPointsInWorld(thick);
  const SurfelExtractionSummary thick_summary = thick_map.ExtractSurfels();
  EXPECT_EQ(thick_summary.num_surfels, 0);
  EXPECT_EQ(thick_summary.rejected_too_thick, 1);
}

TEST(SurfelMapTest, MomentsStayAccurateFarFromTheOrigin) {
  SurfelMap map(RoomMapParams());
  const Eigen::Vector3d far(80000.1, -65000.4, 120.3);
  const Eigen::Vector3d n = Eigen::Vector3d(0.0, 0.6, 0.8);
  const Eigen::Vector3d u = Eigen::Vector3d::UnitX(), v = n.cross(u);
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector3d& p : GridOnPlane(Eigen::Vector3d::Zero(), u, v, 12, 0.3)) points.push_back(far + p);
  map.AddPointsInWorld(points);
  ASSERT_EQ(map.ExtractSurfels().num_surfels, 1);
  EXPECT_LT(NormalAngleDeg(map.surfels()[0].normal, n), 1e-6);
}

}  // namespace
}  // namespace tiltcal::calibrate
