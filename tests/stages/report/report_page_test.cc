#include "stages/report/report_page.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/io/atomic_file.h"
#include "common/io/text_proto.h"
#include "stages/report/report.h"
#include "stages/export/export.h"
#include "stages/report/residual_histogram_svg.h"
#include "stages/report/residual_time_svg.h"
#include "tests/stages/report/synthetic_wall.h"
#include "tests/stages/report/report_params_text.h"
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
  // Over time: 4 bins of 10 s from 0, the third empty.
  s.set_time_start_s(0.0);
  s.set_time_bin_s(10.0);
  for (const int count : {30, 40, 0, 30}) s.add_time_bin_count(count);
  for (const float v : {1.0f, 1.1f, 0.0f, 0.9f}) s.add_time_bin_rms(v);
  for (const float v : {-1.6f, -1.7f, 0.0f, -1.5f}) s.add_time_bin_p05(v);
  for (const float v : {0.0f, 0.1f, 0.0f, -0.1f}) s.add_time_bin_median(v);
  for (const float v : {1.6f, 6.0f, 0.0f, 1.5f}) s.add_time_bin_p95(v);
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
  c.mutable_gravity_in_world()->set_z(-9.81);
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

// Two runs of non-empty bins (0-1 and 3): two bands, two medians, two RMS
// lines; bin 1's p95 of 6 is clipped to +5 (the top of the plot, y = 22).
TEST(ResidualTimeSvg, BandsMedianRmsAndMarks) {
  const std::string svg = ResidualTimeSvg(Histogram("gyro"));
  EXPECT_EQ(Count(svg, "<polygon class=\"band\""), 2u);
  EXPECT_EQ(Count(svg, "<polyline class=\"median\""), 2u);
  EXPECT_EQ(Count(svg, "<polyline class=\"rms\""), 2u);
  EXPECT_EQ(Count(svg, "class=\"sigma3\""), 2u);
  // x of bin i's middle: 30 + (10 i + 5) / 40 * 480; y of r: 82 - 12 r.
  EXPECT_THAT(svg, HasSubstr("<polygon class=\"band\" points=\"90.0,62.8 210.0,22.0 "
                             "210.0,102.4 90.0,101.2\""));
  EXPECT_THAT(svg, HasSubstr("<polyline class=\"median\" points=\"450.0,83.2\""));
  EXPECT_THAT(svg, HasSubstr("<line class=\"sigma3\" x1=\"30\" y1=\"118.0\""));
  proto::ResidualStatistics old;
  old.set_type("lidar");
  EXPECT_THAT(ResidualTimeSvg(old), HasSubstr("lidar: no residuals over time"));
}

// The check against a stored calibration: verdicts, numbers and escaped
// strings; no section without it.
TEST(ReportPage, VerifySectionShowsVerdictsDifferencesAndEscapedStrings) {
  VerifyPage verify;
  verify.link = "verify.txtpb";
  proto::VerifyResult& r = verify.result;
  r.set_verdict(proto::VerifyResult::MOVED);
  r.set_reference("vehicle<7>/calibration.txtpb");
  r.add_verdict_reasons("run<1>: moved: rotation 1.000 deg about b (0.00, 0.00, 1.00)");
  proto::SequenceVerification* s = r.add_sequences();
  s->set_name("run<1>");
  s->set_verdict(proto::VerifyResult::MOVED);
  s->set_chi2(412.5);
  s->set_dof(7);
  s->set_limit(24.3);
  s->mutable_rotation_difference_deg()->set_z(1.0);
  s->set_rotation_difference_sigma(20.3);
  s->mutable_translation_difference_m()->set_x(-0.03);
  s->mutable_detectable_rotation_deg()->set_x(0.05);
  s->mutable_detectable_rotation_deg()->set_z(0.41);
  s->add_reasons("moved: rotation & more");
  proto::SequenceVerification* weak = r.add_sequences();
  weak->set_name("straight");
  weak->set_verdict(proto::VerifyResult::CANNOT_TELL);
  weak->add_reasons("cannot tell: the sequence cannot be calibrated: too little turning");
  const std::string html = FormatHtml("d", Repeatability{}, {}, nullptr, &verify);
  EXPECT_THAT(html, HasSubstr("<section class=\"verify\" id=\"verify\">"));
  EXPECT_THAT(html, HasSubstr("verdict verdict-MOVED\">MOVED</span>"));
  EXPECT_THAT(html, HasSubstr("<code>vehicle&lt;7&gt;/calibration.txtpb</code>"));
  EXPECT_THAT(html, HasSubstr("<li>run&lt;1&gt;: moved: rotation 1.000 deg"));
  EXPECT_THAT(html, HasSubstr("<td>run&lt;1&gt;</td><td class=\"verdict-MOVED\">MOVED</td>"
                              "<td>412.5 / 24.3 (7)</td><td>(+0.000, +0.000, +1.000) (20.3)</td>"
                              "<td>(-30.0, +0.0, +0.0) (0.0)</td>"));
  EXPECT_THAT(html, HasSubstr("<td>(0.05, none, 0.41); (none, none, none); none</td>"));
  EXPECT_THAT(html, HasSubstr("<td class=\"verdict-CANNOT_TELL\">CANNOT_TELL</td>"));
  EXPECT_THAT(html, HasSubstr("<li>moved: rotation &amp; more</li>"));
  EXPECT_THAT(html, HasSubstr("too little turning</li>"));
  EXPECT_THAT(html, Not(HasSubstr("<run<1>")));
  EXPECT_THAT(FormatHtml("d", Repeatability{}, {}), Not(HasSubstr("class=\"verify\"")));
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
  EXPECT_EQ(Count(html, "<svg class=\"time-series\""), 4u);
  EXPECT_THAT(html, HasSubstr("Wall snapshots: maps not written"));
  EXPECT_THAT(html, HasSubstr("<a href=\"./run1/map_rig.pcd\" class=\"pcd\">"));
  EXPECT_THAT(html, HasSubstr("map with the estimate: not written"));
  // Self-contained: nothing fetched, nothing run.
  EXPECT_THAT(html, Not(HasSubstr("<script")));
  EXPECT_THAT(html, Not(HasSubstr("<link")));
  EXPECT_THAT(html, Not(HasSubstr("src=")));  // no maps: no images
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
    // Before: the wall doubled 10 cm behind itself; after: one 1.8 cm sheet.
    const std::vector<double> sheet = {-0.009, -0.003, 0.003, 0.009};
    std::vector<double> doubled = sheet;
    for (const double dx : sheet) doubled.push_back(dx + 0.1);
    ASSERT_TRUE(WriteFileAtomically(dir_.File("run1/map_rig.pcd"),
                                    MapPcdBytes(SyntheticWallScene(doubled)))
                    .ok());
    ASSERT_TRUE(WriteFileAtomically(dir_.File("run1/map_calibrated.pcd"),
                                    MapPcdBytes(SyntheticWallScene(sheet)))
                    .ok());
    proto::CalibrationResult dataset = Calibration(proto::CalibrationResult::OK);
    dataset.mutable_imu_from_lidar()->mutable_translation()->set_x(0.125);
    for (const char* name : {"run1", "run2"}) {
      proto::DatasetSequence* s = dataset.add_sequences();
      s->set_name(name);
      s->set_verdict(proto::CalibrationResult::OK);
      s->set_used(std::string(name) == "run1");
      s->set_consistency_chi2(3.25);
      s->set_consistency_dof(6);
      s->set_consistency_limit(22.46);
      s->set_consistent(true);
    }
    ASSERT_TRUE(WriteTextProto(dir_.File("calibration.txtpb"), dataset).ok());
    paths_.dataset_calibration = dir_.File("calibration.txtpb");
    paths_.sequence_dirs = {dir_.File("run1"), dir_.File("run2")};
    paths_.out = dir_.File("repeatability.txt");
    paths_.out_html = dir_.File("report.html");
    paths_.title = "two runs";
    ASSERT_TRUE(report::Run(paths_, DefaultReportParams(), nullptr).ok());
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
  EXPECT_THAT(html_, HasSubstr("href=\"./run1/map_rig.pcd\""));
  EXPECT_THAT(html_, HasSubstr("href=\"./run1/map_calibrated.pcd\""));
  EXPECT_THAT(html_, HasSubstr("href=\"./run2/calibration.suspect.txtpb\""));
  // The dataset's section first, with its exports open; run1's exports
  // collapsed; run2 (SUSPECT) not exported.
  EXPECT_THAT(html_, HasSubstr("<section class=\"dataset\" id=\"dataset\">"));
  EXPECT_LT(html_.find("id=\"dataset\""), html_.find("id=\"repeatability\""));
  EXPECT_THAT(html_, HasSubstr("<td class=\"tx\">0.125000000</td>"));
  EXPECT_THAT(html_, HasSubstr("<tr><td>run1</td><td>OK</td><td>yes</td><td>3.2</td><td>6</td>"
                               "<td>22.5</td><td>yes</td>"));
  EXPECT_THAT(html_, HasSubstr("<details class=\"exports\" open>"));
  EXPECT_EQ(Count(html_, "<pre class=\"export\""), 12u);  // 6 formats, dataset and run1
  EXPECT_THAT(html_, HasSubstr("verdict SUSPECT (the map with the estimate is &lt;not&gt; "
                               "sharper &amp; that is bad); not exported without --allow_suspect"));
  EXPECT_THAT(html_, HasSubstr("<td>chi2 3.2 / 22.5</td>"));
  // Four snapshots of run1, every image a data: URI; none for run2.
  EXPECT_EQ(Count(html_, "<img class=\"snapshot "), 4u);
  EXPECT_EQ(Count(html_, "src="), Count(html_, "src=\"data:image/png;base64,"));
  EXPECT_THAT(html_, HasSubstr("width=\"600\" height=\"150\""));  // 4 m x 1 m at 150 px/m
  EXPECT_THAT(html_, HasSubstr("rig&#39;s extrinsic (before): this wall&#39;s spread "));
}

// A map that cannot be read, or params out of their bounds: one error
// naming the file or the field, and no output written.
TEST_F(ReportRunTest, MalformedMapOrParamsAreErrorsNamingThem) {
  paths_.out = dir_.File("again.txt");
  paths_.out_html = dir_.File("again.html");
  proto::ReportParams params = DefaultReportParams();
  params.mutable_wall_snapshot()->set_pixels_per_m(0);
  const Status bad_params = report::Run(paths_, params, nullptr);
  EXPECT_THAT(bad_params.message(), HasSubstr("pixels_per_m")) << bad_params.message();
  ASSERT_TRUE(WriteFileAtomically(dir_.File("run1/map_rig.pcd"),
                                  "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 5\nDATA binary\n")
                  .ok());
  const Status bad_map = report::Run(paths_, DefaultReportParams(), nullptr);
  EXPECT_EQ(bad_map.message(),
            dir_.File("run1/map_rig.pcd") + ": PCD truncated: POINTS 5, data for 0");
  EXPECT_FALSE(std::filesystem::exists(paths_.out));
  EXPECT_FALSE(std::filesystem::exists(paths_.out_html));
}

// The page in a real browser: Debian's chromium, headless, loads it from
// disk without console errors, and the DOM it builds has the sections, the
// histograms and the extrinsic of the calibration file.
TEST_F(ReportRunTest, ChromiumLoadsThePage) {
  if (testing::RunCommand("command -v chromium > /dev/null") != 0) {
    GTEST_SKIP() << "chromium is not installed (scripts/setup.sh installs it)";
  }
  // The page with a checker appended (the page itself has no script) that
  // records, once the page has loaded, how many images it has and how many
  // decoded (complete, naturalWidth > 0) in the DOM.
  const std::string checked = dir_.File("report_checked.html");
  ASSERT_TRUE(WriteFileAtomically(
                  checked,
                  html_ + "<script>window.addEventListener('load', () => { const images = "
                          "[...document.images]; document.body.dataset.images = images.length; "
                          "document.body.dataset.decoded = images.filter(i => i.complete && "
                          "i.naturalWidth > 0).length; });</script>\n")
                  .ok());
  auto load = [&](const std::string& page, std::string* dom, std::string* log) {
    const std::string command =
        "chromium --headless --no-sandbox --disable-gpu --no-first-run "
        "--user-data-dir=" + dir_.File("profile") +
        " --enable-logging=stderr --v=0 --virtual-time-budget=2000 --dump-dom file://" + page +
        " 2> " + dir_.File("chromium.log");
    ASSERT_EQ(testing::RunCommand(command, dom), 0) << *dom;
    ASSERT_TRUE(ReadFileToString(dir_.File("chromium.log"), log).ok());
  };
  std::string dom, log;
  load(checked, &dom, &log);
  EXPECT_THAT(log, Not(HasSubstr("CONSOLE"))) << log;
  EXPECT_THAT(dom, HasSubstr("data-images=\"4\" data-decoded=\"4\""));
  // The exports shown are tiltcal_export's output, byte for byte.
  auto unescape = [](std::string text) {
    for (const auto& [from, to] : {std::pair<std::string, std::string>{"&lt;", "<"},
                                   {"&gt;", ">"}, {"&quot;", "\""}, {"&amp;", "&"}}) {
      for (size_t i = text.find(from); i != std::string::npos; i = text.find(from, i + 1)) {
        text.replace(i, from.size(), to);
      }
    }
    return text;
  };
  size_t at = 0;
  for (const std::string& calibration :
       {paths_.dataset_calibration, paths_.sequence_dirs[0] + "/calibration.txtpb"}) {
    for (const char* format : {"fast_lio", "lio_sam", "urdf", "tf_ros1", "tf_ros2", "kalibr"}) {
      const std::string open = std::string("<pre class=\"export\" data-format=\"") + format + "\">";
      at = dom.find(open, at);
      ASSERT_NE(at, std::string::npos) << format;
      at += open.size();
      const std::string shown = unescape(dom.substr(at, dom.find("</pre>", at) - at));
      std::ostringstream expected;
      exporter::ExportOptions options;
      options.format = format;
      ASSERT_TRUE(exporter::Run({calibration, ""}, options, &expected).ok());
      EXPECT_EQ(shown, expected.str()) << calibration << " " << format;
    }
  }
  EXPECT_EQ(Count(dom, "<section class=\"sequence\""), 2u) << dom.substr(0, 2000);
  EXPECT_EQ(Count(dom, "<svg class=\"histogram\""), 8u);
  EXPECT_EQ(Count(dom, "<polyline class=\"normal\""), 8u);
  EXPECT_EQ(Count(dom, "<svg class=\"time-series\""), 8u);
  proto::CalibrationResult file;
  ASSERT_TRUE(ReadTextProto(dir_.File("run1/calibration.txtpb"), &file).ok());
  char qx[64];
  std::snprintf(qx, sizeof(qx), "<td class=\"qx\">%.9f</td>", file.imu_from_lidar().rotation().x());
  EXPECT_THAT(dom, HasSubstr(qx));
  // The dataset's extrinsic shown equals its file's.
  proto::CalibrationResult joint;
  ASSERT_TRUE(ReadTextProto(paths_.dataset_calibration, &joint).ok());
  const size_t dataset_at = dom.find("id=\"dataset\"");
  ASSERT_NE(dataset_at, std::string::npos);
  char tx[64];
  std::snprintf(tx, sizeof(tx), "<td class=\"tx\">%.9f</td>",
                joint.imu_from_lidar().translation().x());
  EXPECT_EQ(dom.find(tx, dataset_at), dom.find("<td class=\"tx\">", dataset_at));
}

}  // namespace
}  // namespace tiltcal::report
