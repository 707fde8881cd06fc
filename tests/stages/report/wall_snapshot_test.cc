#include "stages/report/wall_snapshot.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "stages/report/base64.h"
#include "stages/report/map_pcd.h"
#include "tests/stages/report/report_params_text.h"
#include "tests/stages/report/synthetic_wall.h"

namespace tiltcal::report {
namespace {

// The defaults with a slab 4 m x 0.6 m (the pixel positions below).
proto::WallSnapshotParams Params() {
  proto::WallSnapshotParams params = DefaultReportParams().wall_snapshot();
  params.set_slab_length_m(4.0);
  params.set_slab_depth_m(0.6);
  return params;
}

// Rows of the top view (across the wall) that hold any point.
std::vector<int> OccupiedRows(const DensityImage& image) {
  std::vector<int> rows;
  for (int r = 0; r < image.height; ++r) {
    for (int c = 0; c < image.width; ++c) {
      if (image.counts[static_cast<size_t>(r) * image.width + c] > 0) {
        rows.push_back(r);
        break;
      }
    }
  }
  return rows;
}

TEST(WallSnapshot, FindsTheLargestVerticalPlaneNotTheGround) {
  const auto points = SyntheticWallScene({-0.009, -0.003, 0.003, 0.009});
  const auto slab = FindWall(points, Eigen::Vector3d::UnitZ(), Params());
  ASSERT_TRUE(slab.has_value());
  EXPECT_NEAR(std::abs(slab->across.x()), 1.0, 1e-6);  // the wall's normal
  EXPECT_NEAR(std::abs(slab->along.y()), 1.0, 1e-6);
  EXPECT_NEAR(slab->up.z(), 1.0, 1e-9);
  EXPECT_NEAR(slab->center.x(), 5.5, 1e-6);
  EXPECT_NEAR(slab->center.y(), 0.0, 0.05);
  // Cells z in [0, 1), [1, 2), [2, 3): from half a cell below the lowest
  // centroid (z ~ 0.6) to half a cell above the highest (z ~ 2.5).
  EXPECT_NEAR(slab->center.z() + slab->bottom_m, 0.1, 0.02);
  EXPECT_NEAR(slab->center.z() + slab->top_m, 3.0, 0.02);
  EXPECT_EQ(slab->length_m, 4.0);
  EXPECT_EQ(slab->depth_m, 0.6);
  EXPECT_EQ(slab->cells, 30);  // 10 along y x 3 up
}

// Points beyond the cell grid (|x| / cell_m above 2^20, e.g. a map point
// at 1e30 m) or not finite are left out: the wall found is the one of the
// scene without them (the wall is moved to the cells at x = 0, where an
// out-of-range cell index converted to int would have landed).
TEST(WallSnapshot, PointsBeyondTheGridAreLeftOut) {
  auto points = SyntheticWallScene({-0.009, -0.003, 0.003, 0.009});
  for (Eigen::Vector3f& p : points) p.x() -= 5.0f;
  const auto plain = FindWall(points, Eigen::Vector3d::UnitZ(), Params());
  ASSERT_TRUE(plain.has_value());
  ASSERT_NEAR(plain->center.x(), 0.5, 1e-6);
  for (const float far : {1e30f, -1e30f, 3e6f, -3e6f, INFINITY, NAN}) {
    points.emplace_back(far, 0.5f, 1.5f);
    points.emplace_back(0.5f, far, 1.5f);
    points.emplace_back(0.5f, 0.5f, far);
    points.emplace_back(far, far, far);
  }
  const auto slab = FindWall(points, Eigen::Vector3d::UnitZ(), Params());
  ASSERT_TRUE(slab.has_value());
  EXPECT_EQ(slab->points, plain->points);
  EXPECT_EQ(slab->cells, plain->cells);
  EXPECT_EQ(slab->center, plain->center);
  EXPECT_EQ(slab->across, plain->across);
}

// A 1.8 cm thick wall at 100 px/m fills the two rows of pixels around the
// slab's centre line (rows 29 and 30 of 60) in the top view and the two
// columns 29 and 30 of the side view; the same wall doubled 10 cm behind
// fills two more rows 10 pixels further.
TEST(WallSnapshot, ThicknessAndDoublingShowInPixels) {
  const proto::WallSnapshotParams params = Params();
  const auto thin = SyntheticWallScene({-0.009, -0.003, 0.003, 0.009});
  const auto slab = FindWall(thin, Eigen::Vector3d::UnitZ(), params);
  ASSERT_TRUE(slab.has_value());
  WallSlab s = *slab;
  if (s.across.x() < 0) {  // orient +across towards +x for the pixel checks
    s.across = -s.across;
    s.along = -s.along;
  }
  const DensityImage top = RenderWallView(thin, s, WallView::kTop, 100);
  EXPECT_EQ(top.width, 400);
  EXPECT_EQ(top.height, 60);
  EXPECT_EQ(OccupiedRows(top), (std::vector<int>{29, 30}));
  const DensityImage side = RenderWallView(thin, s, WallView::kSide, 100);
  EXPECT_EQ(side.width, 60);
  EXPECT_EQ(side.height, std::lround((s.top_m - s.bottom_m) * 100));
  std::vector<int> columns;
  for (int c = 0; c < side.width; ++c) {
    for (int r = 0; r < side.height; ++r) {
      if (side.counts[static_cast<size_t>(r) * side.width + c] > 0) {
        columns.push_back(c);
        break;
      }
    }
  }
  EXPECT_EQ(columns, (std::vector<int>{29, 30}));
  // Doubled: a second sheet 10 cm further along +x (rows up the image).
  const auto doubled =
      SyntheticWallScene({-0.009, -0.003, 0.003, 0.009, 0.091, 0.097, 0.103, 0.109});
  EXPECT_EQ(OccupiedRows(RenderWallView(doubled, s, WallView::kTop, 100)),
            (std::vector<int>{19, 20, 29, 30}));
  // Spread: a 1.8 cm wall (sheets ±3, ±9 mm) about 9 mm, doubled 10 cm
  // (half the points 10 cm away) about 7 cm.
  EXPECT_NEAR(WallSpread(thin, s), 0.0089, 0.0005);
  EXPECT_GT(WallSpread(doubled, s), 0.05);
  // Shading: empty white, the saturation and above black.
  DensityImage d;
  d.width = 3;
  d.height = 1;
  d.counts = {0, 3, 100};
  const GrayImage g = ShadeDensity(d, 15);
  EXPECT_EQ(g.pixels, (std::vector<uint8_t>{255, 128, 0}));  // 255 (1 - log 4 / log 16) = 127.5
}

TEST(WallSnapshot, NoVerticalPlaneGivesNothing) {
  std::vector<Eigen::Vector3f> ground;
  for (double x = -6; x < 6; x += 0.1) {
    for (double y = -6; y < 6; y += 0.1) ground.emplace_back(x, y, 0.0f);
  }
  EXPECT_FALSE(FindWall(ground, Eigen::Vector3d::UnitZ(), DefaultReportParams().wall_snapshot())
                   .has_value());
}

TEST(Base64, Rfc4648Vectors) {
  EXPECT_EQ(EncodeBase64(""), "");
  EXPECT_EQ(EncodeBase64("f"), "Zg==");
  EXPECT_EQ(EncodeBase64("fo"), "Zm8=");
  EXPECT_EQ(EncodeBase64("foo"), "Zm9v");
  EXPECT_EQ(EncodeBase64("foob"), "Zm9vYg==");
  EXPECT_EQ(EncodeBase64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(EncodeBase64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(EncodeBase64(std::string("\xff\xfe", 2)), "//4=");
}

std::string Pcd(const std::string& fields_lines, const std::string& data) {
  return "# .PCD v0.7\nVERSION 0.7\n" + fields_lines + "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA binary\n" +
         data;
}

TEST(MapPcd, ReadsXyzAndSkipsFurtherFields) {
  std::string data;
  const float xyz[2][3] = {{1.5f, -2.0f, 3.25f}, {0.0f, 7.0f, -1.0f}};
  for (int i = 0; i < 2; ++i) {
    data.append(reinterpret_cast<const char*>(xyz[i]), 12);
    const uint32_t scan = 40 + i;
    data.append(reinterpret_cast<const char*>(&scan), 4);
  }
  std::vector<Eigen::Vector3f> points;
  ASSERT_TRUE(ParseMapPcd(Pcd("FIELDS x y z scan\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n",
                              data),
                          "m.pcd", &points)
                  .ok());
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[0], Eigen::Vector3f(1.5f, -2.0f, 3.25f));
  EXPECT_EQ(points[1], Eigen::Vector3f(0.0f, 7.0f, -1.0f));
  const Status truncated = ParseMapPcd(
      Pcd("FIELDS x y z scan\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n", data.substr(0, 20)),
      "m.pcd", &points);
  EXPECT_EQ(truncated.message(), "m.pcd: PCD truncated: POINTS 2, data for 1");
  EXPECT_EQ(ParseMapPcd(Pcd("FIELDS y x z\nSIZE 4 4 4\nTYPE F F F\n", data), "m.pcd", &points)
                .message(),
            "m.pcd: PCD fields must start with x y z (float32)");
  EXPECT_EQ(ParseMapPcd("FIELDS x y z\n", "m.pcd", &points).message(),
            "m.pcd: PCD header without a DATA line");
}

}  // namespace
}  // namespace tiltcal::report
