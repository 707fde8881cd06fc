#include "stages/report/html_escape.h"

#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "stages/report/report_page.h"
#include "stages/report/residual_histogram_svg.h"
#include "stages/report/residual_time_svg.h"

namespace tiltcal::report {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr char kPayload[] = "\"><img src=x onerror=alert(1)>'";

TEST(EscapeHtml, EscapesTheFiveMarkupCharacters) {
  EXPECT_EQ(EscapeHtml("a & b < c > d \" e ' f"), "a &amp; b &lt; c &gt; d &quot; e &#39; f");
  EXPECT_EQ(EscapeHtml(kPayload), "&quot;&gt;&lt;img src=x onerror=alert(1)&gt;&#39;");
  EXPECT_EQ(EscapeHtml("plain\ntext, ±3"), "plain\ntext, ±3");
}

TEST(RelativeHref, PercentEncodesAndKeepsItRelative) {
  EXPECT_EQ(RelativeHref("run1/calibration.txtpb"), "./run1/calibration.txtpb");
  EXPECT_EQ(RelativeHref("../out/map_rig.pcd"), "../out/map_rig.pcd");
  // No scheme can form: the colon is encoded and the path starts with ./
  EXPECT_EQ(RelativeHref("javascript:alert(1)/calibration.txtpb"),
            "./javascript%3Aalert%281%29/calibration.txtpb");
  EXPECT_EQ(RelativeHref("a b#c?d%e\"<\\\n/x"), "./a%20b%23c%3Fd%25e%22%3C%5C%0A/x");
  EXPECT_EQ(RelativeHref("r\xc3\xa9sum\xc3\xa9"), "./r%C3%A9sum%C3%A9");
  // Not relative: no link.
  EXPECT_EQ(RelativeHref(""), std::nullopt);
  EXPECT_EQ(RelativeHref("/etc/passwd"), std::nullopt);
  EXPECT_EQ(RelativeHref("//host/share"), std::nullopt);
}

TEST(LinkOrText, LinksRelativePathsAndShowsTheRestAsText) {
  EXPECT_EQ(LinkOrText("run1/map_rig.pcd", " class=\"pcd\""),
            "<a href=\"./run1/map_rig.pcd\" class=\"pcd\">run1/map_rig.pcd</a>");
  EXPECT_EQ(LinkOrText("javascript:alert(1)"),
            "<a href=\"./javascript%3Aalert%281%29\">javascript:alert(1)</a>");
  EXPECT_EQ(LinkOrText("/abs/<b>.pcd"), "/abs/&lt;b&gt;.pcd");
}

// The SVG builders and the page pass every string through EscapeHtml and
// every path through LinkOrText.
TEST(HtmlEscape, EveryBuilderUsesIt) {
  proto::ResidualStatistics s;
  s.set_type(kPayload);
  s.set_count(10);
  s.set_histogram_min(-5);
  s.set_histogram_bin_width(1);
  for (int i = 0; i < 10; ++i) s.add_histogram_counts(1);
  s.set_time_bin_s(1);
  s.add_time_bin_count(10);
  s.add_time_bin_rms(1);
  s.add_time_bin_p05(-1);
  s.add_time_bin_median(0);
  s.add_time_bin_p95(1);
  proto::ResidualStatistics empty;
  empty.set_type(kPayload);
  SequencePage page;
  page.name = kPayload;
  page.calibration.add_verdict_reasons(kPayload);
  *page.calibration.add_residual_statistics() = s;
  *page.calibration.add_residual_statistics() = empty;
  page.calibration_link = "javascript:alert(1)/calibration.txtpb";
  page.map_rig_link = "/abs/map_rig.pcd";
  page.map_calibrated_link = std::string(kPayload) + "/map_calibrated.pcd";
  page.exports = {{"urdf", kPayload}};
  DatasetPage dataset;
  dataset.calibration_link = "javascript:alert(1)";
  dataset.exports_note = kPayload;
  proto::DatasetSequence* q = dataset.calibration.add_sequences();
  q->set_name(kPayload);
  q->set_reason(kPayload);
  Repeatability repeatability;
  repeatability.sequences.emplace_back();
  repeatability.sequences.back().label = kPayload;
  repeatability.suspect_set_aside = {kPayload};
  for (const std::string& html :
       {ResidualHistogramSvg(s), ResidualTimeSvg(s), ResidualHistogramSvg(empty),
        ResidualTimeSvg(empty), FormatHtml(kPayload, repeatability, {page}, &dataset)}) {
    EXPECT_THAT(html, Not(HasSubstr("<img"))) << html;
    EXPECT_THAT(html, Not(HasSubstr("alert(1)>"))) << html;
    EXPECT_THAT(html, Not(HasSubstr("href=\"javascript"))) << html;
    EXPECT_THAT(html, Not(HasSubstr("href=\"/"))) << html;
  }
  const std::string html = FormatHtml(kPayload, repeatability, {page}, &dataset);
  EXPECT_THAT(html, HasSubstr("<a href=\"./javascript%3Aalert%281%29/calibration.txtpb\">"));
  EXPECT_THAT(html, HasSubstr("CloudCompare): /abs/map_rig.pcd</li>"));
  EXPECT_THAT(html, HasSubstr("--calibration=&#39;javascript:alert(1)/calibration.txtpb&#39;"));
}

}  // namespace
}  // namespace tiltcal::report
