#include "stages/report/residual_time_svg.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "stages/report/html_escape.h"

namespace tiltcal::report {

namespace {

// Plot area in SVG units: x in [kLeft, kLeft + kWidth], y down from kTop;
// r in [-kRange, kRange].
constexpr double kLeft = 30, kTop = 22, kWidth = 480, kHeight = 120, kRange = 5;

// Time [t0, t1] s and normalised residual r to SVG coordinates.
struct PlotScale {
  double t0, t1;
  double X(double t) const { return kLeft + (t - t0) / (t1 - t0) * kWidth; }
  double Y(double r) const {
    return kTop + kHeight * 0.5 * (1.0 - std::clamp(r, -kRange, kRange) / kRange);
  }
};

// Each run of non-empty bins as a band (p95 forward, p05 back), a median and
// an RMS line.
std::string BinRunsSvg(const proto::ResidualStatistics& s, const PlotScale& scale) {
  const int bins = s.time_bin_count_size();
  const double w = s.time_bin_s();
  std::vector<std::pair<int, int>> runs;
  for (int i = 0; i < bins; ++i) {
    if (s.time_bin_count(i) <= 0) continue;
    if (runs.empty() || runs.back().second != i) runs.push_back({i, i + 1});
    else runs.back().second = i + 1;
  }
  std::string svg;
  for (const auto& [first, end] : runs) {
    std::string band, median, rms;
    for (int i = first; i < end; ++i) {
      const double x = scale.X(scale.t0 + (i + 0.5) * w);
      band += fmt::format("{:.1f},{:.1f} ", x, scale.Y(s.time_bin_p95(i)));
      median += fmt::format("{:.1f},{:.1f} ", x, scale.Y(s.time_bin_median(i)));
      rms += fmt::format("{:.1f},{:.1f} ", x, scale.Y(s.time_bin_rms(i)));
    }
    for (int i = end - 1; i >= first; --i) {
      band += fmt::format("{:.1f},{:.1f} ", scale.X(scale.t0 + (i + 0.5) * w),
                          scale.Y(s.time_bin_p05(i)));
    }
    band.pop_back();
    median.pop_back();
    rms.pop_back();
    svg += fmt::format(
        "<polygon class=\"band\" points=\"{}\" fill=\"#7aa6d6\" fill-opacity=\"0.6\" "
        "stroke=\"#7aa6d6\"/>\n"
        "<polyline class=\"median\" points=\"{}\" fill=\"none\" stroke=\"#1f4e79\" "
        "stroke-width=\"1.5\"/>\n"
        "<polyline class=\"rms\" points=\"{}\" fill=\"none\" stroke=\"#d35400\" "
        "stroke-width=\"1.2\"/>\n",
        band, median, rms);
  }
  return svg;
}

}  // namespace

std::string ResidualTimeSvg(const proto::ResidualStatistics& s) {
  const int bins = s.time_bin_count_size();
  const double w = s.time_bin_s();
  if (bins == 0 || !(w > 0) || s.time_bin_rms_size() != bins || s.time_bin_p05_size() != bins ||
      s.time_bin_median_size() != bins || s.time_bin_p95_size() != bins) {
    return fmt::format("<p class=\"no-time-series\">{}: no residuals over time in the "
                       "calibration file</p>",
                       EscapeHtml(s.type()));
  }
  const double t0 = s.time_start_s();
  const double t1 = t0 + bins * w;
  const PlotScale scale{t0, t1};
  std::string svg = fmt::format(
      "<svg class=\"time-series\" data-type=\"{0}\" xmlns=\"http://www.w3.org/2000/svg\" "
      "width=\"530\" height=\"178\" viewBox=\"0 0 530 178\" role=\"img\">\n"
      "<title>{0}: normalised residuals over time</title>\n"
      "<text x=\"270\" y=\"14\" text-anchor=\"middle\" font-size=\"12\">{0} over time "
      "({1} bins of {2:.2g} s)</text>\n",
      EscapeHtml(s.type()), bins, w);
  svg += BinRunsSvg(s, scale);
  for (const double r : {-3.0, 3.0}) {
    svg += fmt::format(
        "<line class=\"sigma3\" x1=\"{0}\" y1=\"{1:.1f}\" x2=\"{2}\" y2=\"{1:.1f}\" "
        "stroke=\"#888\" stroke-dasharray=\"3,3\"/>\n",
        kLeft, scale.Y(r), kLeft + kWidth);
  }
  svg += fmt::format(
      "<line x1=\"{0}\" y1=\"{1:.1f}\" x2=\"{2}\" y2=\"{1:.1f}\" stroke=\"#bbb\"/>\n"
      "<rect x=\"{0}\" y=\"{3}\" width=\"{4}\" height=\"{5}\" fill=\"none\" stroke=\"#000\"/>\n",
      kLeft, scale.Y(0.0), kLeft + kWidth, kTop, kWidth, kHeight);
  for (const double r : {-5.0, -3.0, 0.0, 3.0, 5.0}) {
    svg += fmt::format("<text x=\"{}\" y=\"{:.1f}\" text-anchor=\"end\" font-size=\"10\">{:g}"
                       "</text>\n",
                       kLeft - 4, scale.Y(r) + 3, r);
  }
  for (int k = 0; k <= 4; ++k) {
    const double t = t0 + k * (t1 - t0) / 4;
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{}\" text-anchor=\"middle\" font-size=\"10\">"
                       "{:.1f}</text>\n",
                       scale.X(t), kTop + kHeight + 13, t);
  }
  svg += fmt::format(
      "<text x=\"270\" y=\"{}\" text-anchor=\"middle\" font-size=\"10\">t, s; r / sigma "
      "(band: 5-95 %, blue: median, orange: RMS, dashed: ±3)</text>\n</svg>\n",
      kTop + kHeight + 27);
  return svg;
}

}  // namespace tiltcal::report
