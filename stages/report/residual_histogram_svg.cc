#include "stages/report/residual_histogram_svg.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "stages/report/html_escape.h"

namespace tiltcal::report {
namespace {

constexpr double kMaxDensity = 0.6;  // the normal's peak is 0.399

double NormalDensity(double r) { return std::exp(-0.5 * r * r) / std::sqrt(2.0 * M_PI); }

}  // namespace

std::string ResidualHistogramSvg(const proto::ResidualStatistics& s) {
  // Plot area in SVG units: x in [kLeft, kLeft + kWidth], y down from kTop.
  constexpr double kLeft = 30, kTop = 22, kWidth = 240, kHeight = 110;
  const int bins = s.histogram_counts_size();
  const double w = s.histogram_bin_width();
  if (bins == 0 || w <= 0 || s.count() <= 0) {
    return fmt::format("<p class=\"no-histogram\">{}: no histogram in the calibration file</p>",
                       EscapeHtml(s.type()));
  }
  const double lo = s.histogram_min();
  const double hi = lo + bins * w;
  auto x_of = [&](double r) { return kLeft + (r - lo) / (hi - lo) * kWidth; };
  auto y_of = [&](double density) {
    return kTop + kHeight * (1.0 - std::min(density, kMaxDensity) / kMaxDensity);
  };
  std::string svg = fmt::format(
      "<svg class=\"histogram\" data-type=\"{0}\" xmlns=\"http://www.w3.org/2000/svg\" "
      "width=\"300\" height=\"168\" viewBox=\"0 0 300 168\" role=\"img\">\n"
      "<title>{0}: normalised residuals against N(0,1)</title>\n"
      "<text x=\"150\" y=\"14\" text-anchor=\"middle\" font-size=\"12\">{0}: N = {1}, "
      "RMS {2:.2f}, outside ±5: {3}</text>\n",
      EscapeHtml(s.type()), s.count(), s.rms(), s.histogram_below() + s.histogram_above());
  for (int i = 0; i < bins; ++i) {
    const double density = s.histogram_counts(i) / (static_cast<double>(s.count()) * w);
    const double y = y_of(density);
    svg += fmt::format(
        "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"#7aa6d6\"/>\n",
        x_of(lo + i * w), y, kWidth / bins, kTop + kHeight - y);
  }
  std::string curve;
  for (double r = lo; r <= hi + 1e-9; r += (hi - lo) / 100) {
    curve += fmt::format("{}{:.1f},{:.1f}", curve.empty() ? "" : " ", x_of(r),
                         y_of(NormalDensity(r)));
  }
  svg += fmt::format(
      "<polyline class=\"normal\" points=\"{}\" fill=\"none\" stroke=\"#c0392b\" "
      "stroke-width=\"1.5\"/>\n",
      curve);
  for (const double r : {-3.0, 3.0}) {
    svg += fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{1}\" x2=\"{0:.1f}\" y2=\"{2}\" stroke=\"#888\" "
        "stroke-dasharray=\"3,3\"/>\n",
        x_of(r), kTop, kTop + kHeight);
  }
  svg += fmt::format(
      "<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"#000\"/>\n", kLeft,
      kTop + kHeight, kLeft + kWidth);
  for (const double r : {lo, -3.0, 0.0, 3.0, hi}) {
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{}\" text-anchor=\"middle\" font-size=\"10\">"
                       "{:g}</text>\n",
                       x_of(r), kTop + kHeight + 14, r);
  }
  svg += fmt::format("<text x=\"150\" y=\"{}\" text-anchor=\"middle\" font-size=\"10\">"
                     "r / sigma (bars: data, line: N(0,1), dashed: ±3)</text>\n</svg>\n",
                     kTop + kHeight + 28);
  return svg;
}

}  // namespace tiltcal::report
