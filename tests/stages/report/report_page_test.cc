#include "stages/report/report_page.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/io/atomic_file.h"
#include "common/io/text_proto.h"
#include "stages/report/report.h"
#include "stages/report/residual_histogram_svg.h"
#include "tests/testing/test_env.h"

namespace tiltcal::report {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t i = text.find(what); i != std::string::npos; i = text.find(what, i + 1)) ++n;
  return n;
}

proto::ResidualStatistics Histogram(const std::string& type) {
  proto::ResidualStatistics s;
  s.set_type(type);
  s.set_count(100);
  s.set_rms(1.02);
  s.set_histogram_min(-5);
  s.set_histogram_bin_width(0.25);
  for (int i = 0; i < 40; ++i) s.add_histogram_counts(i == 20 ? 60 : (i == 19 ? 38 : 0));
  s.set_histogram_above(2);
  return s;
}

// A calibration as tiltcal_calibrate writes it (the fields the page shows).
proto::CalibrationResult Calibration(proto::CalibrationResult::Verdict verdict) {
  proto::CalibrationResult c;
  auto* q = c.mutable_imu_from_lidar()->mutable_rotation();
  q->set_w(0.899907089822004);
  q->set_x(0.245231085988330);
  q->set_y(-0.046353699228730);
  q->set_z(0.357603521684125);
  c.mutable_imu_from_lidar()->mutable_translation()->set_x(0.12);
  c.mutable_imu_from_lidar()->mutable_translation()->set_y(-0.34);
  c.mutable_imu_from_lidar()->mutable_translation()->set_z(0.56);
  c.set_time_offset_s(0.0123);
  c.set_verdict(verdict);
  c.add_verdict_reasons("the map with the estimate is <not> sharper & that is bad");
  c.mutable_map_sharpness_rig()->set_median_thickness_m(0.0312);
  c.mutable_map_sharpness_rig()->set_planar_surfels(900);
  c.mutable_map_sharpness_estimate()->set_median_thickness_m(0.0121);
  c.mutable_map_sharpness_estimate()->set_planar_surfels(1100);
  for (const char* type : {"gyro", "accel", "lidar", "ground"}) {
    *c.add_residual_statistics() = Histogram(type);
  }
  return c;
}

TEST(ResidualHistogramSvg, BarsCurveAndMarks) {
  const std::string svg = ResidualHistogramSvg(Histogram("lidar"));
  EXPECT_EQ(Count(svg, "<rect "), 40u);
  EXPECT_EQ(Count(svg, "<polyline class=\"normal\""), 1u);
  EXPECT_EQ(Count(svg, "stroke-dasharray"), 2u);  // ±3
  EXPECT_THAT(svg, HasSubstr("lidar: N = 100, RMS 1.02, outside ±5: 2"));
  // Bin 20 holds 60 of 100 in a 0.25 bin: density 2.4, clipped to the top
  // of the plot (y = 22); an empty bin has height 0.
  EXPECT_THAT(svg, HasSubstr("<rect x=\"150.0\" y=\"22.0\" width=\"6.0\" height=\"110.0\""));
  EXPECT_THAT(svg, HasSubstr("<rect x=\"30.0\" y=\"132.0\" width=\"6.0\" height=\"0.0\""));
  proto::ResidualStatistics old;
  old.set_type("gyro");
  old.set_count(10);
  EXPECT_THAT(ResidualHistogramSvg(old), HasSubstr("gyro: no histogram in the calibration file"));
}

TEST(ReportPage, SectionsShowVerdictExtrinsicSharpnessAndEscapedReasons) {
  SequencePage page;
  page.name = "run1";
  page.calibration = Calibration(proto::CalibrationResult::WEAK);
  page.calibration_link = "run1/calibration.txtpb";
  page.map_rig_link = "run1/map_rig.pcd";
  const std::string html = FormatHtml("demo <flat>", Repeatability{}, {page});
  EXPECT_THAT(html, HasSubstr("<title>demo &lt;flat&gt;</title>"));
  EXPECT_THAT(html, HasSubstr("<section class=\"sequence\" id=\"sequence-run1\">"));
  EXPECT_THAT(html, HasSubstr("verdict-WEAK\">WEAK</span>"));
  EXPECT_THAT(html,
              HasSubstr("<li>the map with the estimate is &lt;not&gt; sharper &amp; that is bad</li>"));
  EXPECT_THAT(html, HasSubstr("<td class=\"qx\">0.245231086</td>"));
  EXPECT_THAT(html, HasSubstr("<td class=\"tz\">0.560000000</td>"));
  EXPECT_THAT(html, HasSubstr("<td class=\"before\">31.20</td>"));
  EXPECT_THAT(html, HasSubstr("<td class=\"after\">12.10</td>"));
  EXPECT_THAT(html, HasSubstr("after / before: 0.388"));
  EXPECT_EQ(Count(html, "<svg class=\"histogram\""), 4u);
  EXPECT_THAT(html, HasSubstr("<a class=\"pcd\" href=\"run1/map_rig.pcd\">"));
  EXPECT_THAT(html, HasSubstr("map with the estimate: not written"));
  // Self-contained: nothing fetched, nothing run.
  EXPECT_THAT(html, Not(HasSubstr("<script")));
  EXPECT_THAT(html, Not(HasSubstr("<link")));
  EXPECT_THAT(html, Not(HasSubstr("src=")));
}

// Two sequence folders as the pipeline leaves them: run1 calibrated (with
// its maps), run2 SUSPECT and set aside.
class ReportRunTest : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const char* name : {"run1", "run2"}) {
      std::filesystem::create_directories(dir_.File(name));
    }
    ASSERT_TRUE(WriteTextProto(dir_.File("run1/calibration.txtpb"),
                               Calibration(proto::CalibrationResult::OK))
                    .ok());
    ASSERT_TRUE(WriteTextProto(dir_.File("run2/calibration.suspect.txtpb"),
                               Calibration(proto::CalibrationResult::SUSPECT))
                    .ok());
    for (const char* map : {"run1/map_rig.pcd", "run1/map_calibrated.pcd"}) {
      ASSERT_TRUE(WriteFileAtomically(dir_.File(map), "pcd").ok());
    }
    paths_.sequence_dirs = {dir_.File("run1"), dir_.File("run2")};
    paths_.out = dir_.File("repeatability.txt");
    paths_.out_html = dir_.File("report.html");
    paths_.title = "two runs";
    ASSERT_TRUE(report::Run(paths_, nullptr).ok());
    ASSERT_TRUE(ReadFileToString(paths_.out_html, &html_).ok());
  }

  testing::TempDir dir_;
  ReportPaths paths_;
  std::string html_;
};

TEST_F(ReportRunTest, PageHasEverySequenceAndRelativeLinks) {
  EXPECT_THAT(html_, HasSubstr("<table id=\"repeatability\">"));
  EXPECT_THAT(html_, HasSubstr("<section class=\"sequence\" id=\"sequence-run1\">"));
  EXPECT_THAT(html_, HasSubstr("id=\"sequence-run2\">\n<h2>run2: <span class=\"verdict "
                               "verdict-SUSPECT\">SUSPECT</span> (set aside)</h2>"));
  EXPECT_THAT(html_, HasSubstr("SUSPECT, set aside (not in the rows above): "));
  EXPECT_THAT(html_, HasSubstr("href=\"run1/map_rig.pcd\""));
  EXPECT_THAT(html_, HasSubstr("href=\"run1/map_calibrated.pcd\""));
  EXPECT_THAT(html_, HasSubstr("href=\"run2/calibration.suspect.txtpb\""));
}

// The page in a real browser: Debian's chromium, headless, loads it from
// disk without console errors, and the DOM it builds has the sections, the
// histograms and the extrinsic of the calibration file.
TEST_F(ReportRunTest, ChromiumLoadsThePage) {
  if (testing::RunCommand("command -v chromium > /dev/null") != 0) {
    GTEST_SKIP() << "chromium is not installed (scripts/setup.sh installs it)";
  }
  const std::string command =
      "chromium --headless --no-sandbox --disable-gpu --no-first-run "
      "--user-data-dir=" + dir_.File("profile") +
      " --enable-logging=stderr --v=0 --dump-dom file://" + paths_.out_html +
      " 2> " + dir_.File("chromium.log");
  std::string dom;
  ASSERT_EQ(testing::RunCommand(command, &dom), 0) << dom;
  std::string log;
  ASSERT_TRUE(ReadFileToString(dir_.File("chromium.log"), &log).ok());
  EXPECT_THAT(log, Not(HasSubstr("CONSOLE"))) << log;
  EXPECT_EQ(Count(dom, "<section class=\"sequence\""), 2u) << dom.substr(0, 2000);
  EXPECT_EQ(Count(dom, "<svg class=\"histogram\""), 8u);
  EXPECT_EQ(Count(dom, "<polyline class=\"normal\""), 8u);
  proto::CalibrationResult file;
  ASSERT_TRUE(ReadTextProto(dir_.File("run1/calibration.txtpb"), &file).ok());
  char qx[64];
  std::snprintf(qx, sizeof(qx), "<td class=\"qx\">%.9f</td>", file.imu_from_lidar().rotation().x());
  EXPECT_THAT(dom, HasSubstr(qx));
}

}  // namespace
}  // namespace tiltcal::report
