#include "stages/report/report_page.h"

#include <cmath>

#include <fmt/format.h>

#include "common/geometry/angles.h"
#include "common/geometry/euler_angles.h"
#include "common/io/eigen_proto.h"
#include "common/io/escaping.h"
#include "stages/report/html_escape.h"
#include "stages/report/residual_histogram_svg.h"
#include "stages/report/residual_time_svg.h"

namespace tiltcal::report {
namespace {

constexpr char kStyle[] =
    "body{font-family:sans-serif;margin:2em;max-width:70em;color:#222}"
    "table{border-collapse:collapse;margin:0.5em 0}"
    "td,th{border:1px solid #ccc;padding:2px 8px;text-align:right}"
    "th:first-child,td:first-child{text-align:left}"
    ".verdict-OK{color:#1e7b34}.verdict-WEAK{color:#a06800}.verdict-SUSPECT{color:#b00020}"
    ".verdict-HOLDS{color:#1e7b34}.verdict-CANNOT_TELL{color:#a06800}.verdict-MOVED{color:#b00020}"
    ".histograms,.time-series-plots,.side-views,.snapshot-views{display:flex;flex-wrap:wrap;"
    "gap:1em}"
    "figure{margin:0.3em 0}figcaption{font-size:90%}"
    "img.snapshot{border:1px solid #999;image-rendering:pixelated;display:block}"
    "pre.export{border:1px solid #ddd;padding:6px;overflow-x:auto;user-select:all}"
    "section{border-top:2px solid #ccc;margin-top:2em}"
    "code,pre{background:#f4f4f4;padding:1px 4px}";

std::string VerdictName(const proto::CalibrationResult& c) {
  return c.verdict() == proto::CalibrationResult::VERDICT_UNSET
             ? "UNSET"
             : proto::CalibrationResult::Verdict_Name(c.verdict());
}

std::string RowCells(const Row& row, bool errors, bool consistency) {
  std::string cells = "<td>" + EscapeHtml(row.label) + "</td>";
  for (int i = 0; i < 3; ++i) cells += fmt::format("<td>{:.2f}</td>", row.translation_cm[i]);
  for (int i = 0; i < 3; ++i) cells += fmt::format("<td>{:.3f}</td>", row.euler123_deg[i]);
  cells += fmt::format("<td>{:.3f}</td>", row.time_offset_ms);
  if (errors) {
    if (row.has_errors) {
      cells += fmt::format("<td>{:.3f}</td>", row.rotation_error_deg);
      for (int i = 0; i < 3; ++i) {
        cells += fmt::format("<td>{:.2f}</td>", row.translation_error_cm[i]);
      }
      cells += fmt::format("<td>{:.3f}</td>", row.time_offset_error_ms);
    } else {
      cells += "<td></td><td></td><td></td><td></td><td></td>";
    }
  }
  cells += fmt::format("<td class=\"verdict-{0}\">{0}</td>", EscapeHtml(row.verdict));
  if (consistency) cells += "<td>" + EscapeHtml(row.consistency) + "</td>";
  return "<tr>" + cells + "</tr>\n";
}

std::string RepeatabilityTable(const Repeatability& r) {
  bool errors = r.mean.has_errors;
  for (const Row& row : r.sequences) errors = errors || row.has_errors;
  std::string out =
      "<h2>Repeatability</h2>\n<p>imu_from_lidar: r_b^{lb} in cm, C_bl as 1-2-3 Euler angles "
      "(C = Rz(θ3) Ry(θ2) Rx(θ1)) in deg, τ in ms (t_imu = t_lidar + τ); the sigma row holds "
      "the per-component σ of the SO(3) deviations.</p>\n<table id=\"repeatability\">\n<tr>"
      "<th>sequence</th><th>r_x</th><th>r_y</th><th>r_z</th><th>θ1</th><th>θ2</th><th>θ3</th>"
      "<th>τ</th>";
  if (errors) out += "<th>rot err</th><th>x err</th><th>y err</th><th>z err</th><th>τ err</th>";
  const bool consistency = r.joint.has_value();
  out += consistency ? "<th>verdict</th><th>consistency with the joint value (χ² / limit)</th>"
                       "</tr>\n"
                     : "<th>verdict</th></tr>\n";
  for (const Row& row : r.sequences) out += RowCells(row, errors, consistency);
  out += RowCells(r.mean, errors, consistency) + RowCells(r.sigma, errors, consistency);
  if (r.measured) out += RowCells(*r.measured, errors, consistency);
  if (r.joint) out += RowCells(*r.joint, errors, consistency);
  out += "</table>\n";
  for (const std::string& name : r.suspect_set_aside) {
    out += "<p>SUSPECT, set aside (not in the rows above): " + EscapeHtml(name) + "</p>\n";
  }
  return out;
}

std::string ExtrinsicTable(const proto::CalibrationResult& c) {
  const Rigid3d t = ToEigen(c.imu_from_lidar());
  const Eigen::Vector3d euler_deg =
      geometry::RadToDeg(geometry::Euler123FromRotation(t.rotation.toRotationMatrix()));
  const auto& rs = c.rotation_sigma_deg();
  const auto& ts = c.translation_sigma_m();
  return fmt::format(
      "<table class=\"extrinsic\">\n"
      "<tr><th></th><th>x</th><th>y</th><th>z</th><th>w</th><th>1-σ (x y z)</th></tr>\n"
      "<tr><td>C_bl quaternion</td><td class=\"qx\">{:.9f}</td><td class=\"qy\">{:.9f}</td>"
      "<td class=\"qz\">{:.9f}</td><td class=\"qw\">{:.9f}</td>"
      "<td>{:.3f} {:.3f} {:.3f} deg (about the LiDAR axes)</td></tr>\n"
      "<tr><td>C_bl 1-2-3 Euler, deg</td><td>{:.3f}</td><td>{:.3f}</td><td>{:.3f}</td>"
      "<td></td><td></td></tr>\n"
      "<tr><td>r_b^{{lb}}, m</td><td class=\"tx\">{:.9f}</td><td class=\"ty\">{:.9f}</td>"
      "<td class=\"tz\">{:.9f}</td><td></td><td>{:.4f} {:.4f} {:.4f} m</td></tr>\n"
      "<tr><td>τ, s (t_imu = t_lidar + τ)</td><td class=\"tau\">{:.9f}</td><td></td><td></td>"
      "<td></td><td>{:.6f} s</td></tr>\n</table>\n",
      t.rotation.x(), t.rotation.y(), t.rotation.z(), t.rotation.w(), rs.x(), rs.y(), rs.z(),
      euler_deg.x(), euler_deg.y(), euler_deg.z(), t.translation.x(), t.translation.y(),
      t.translation.z(), ts.x(), ts.y(), ts.z(), c.time_offset_s(), c.time_offset_sigma_s());
}

std::string SharpnessTable(const proto::CalibrationResult& c) {
  const double rig_m = c.map_sharpness_rig().median_thickness_m();
  const double est_m = c.map_sharpness_estimate().median_thickness_m();
  return fmt::format(
      "<table class=\"sharpness\">\n<tr><th>map</th><th>median surfel thickness, mm</th>"
      "<th>planar surfels</th></tr>\n"
      "<tr><td>rig's extrinsic (before)</td><td class=\"before\">{:.2f}</td><td>{}</td></tr>\n"
      "<tr><td>estimate (after)</td><td class=\"after\">{:.2f}</td><td>{}</td></tr>\n"
      "</table>\n<p>after / before: {}; the estimate moved {:.3f} deg and {:.1f} mm from the "
      "rig.</p>\n",
      1e3 * rig_m, c.map_sharpness_rig().planar_surfels(), 1e3 * est_m,
      c.map_sharpness_estimate().planar_surfels(),
      rig_m > 0 ? fmt::format("{:.3f}", est_m / rig_m) : std::string("n/a"),
      c.rotation_from_rig_deg(), 1e3 * c.translation_from_rig_m());
}

std::string FilesList(const SequencePage& s) {
  std::string out = "<ul class=\"files\">\n";
  out += "<li>calibration: " + LinkOrText(s.calibration_link) + "</li>\n";
  for (const auto& [label, link] : {std::pair<const char*, const std::string&>{
                                        "map with the rig's extrinsic", s.map_rig_link},
                                    {"map with the estimate", s.map_calibrated_link}}) {
    out += link.empty() ? fmt::format("<li>{}: not written</li>\n", label)
                        : fmt::format("<li>{} (PCD, pcl_viewer or CloudCompare): {}</li>\n",
                                      label, LinkOrText(link, " class=\"pcd\""));
  }
  return out + "</ul>\n";
}

std::string SnapshotFigure(const SnapshotImage& image, const std::string& classes,
                           const std::string& caption) {
  return fmt::format(
      "<figure><img class=\"snapshot {0}\" src=\"{1}\" width=\"{2}\" height=\"{3}\" "
      "alt=\"{4}\"><figcaption>{4}</figcaption></figure>\n",
      classes, image.data_uri, image.width, image.height, EscapeHtml(caption));
}

// The wall from above and from the side, rig's extrinsic and estimate.
std::string SnapshotsBlock(const SequencePage& s) {
  const WallSnapshots& w = s.snapshots;
  if (!w.note.empty() || w.top_rig.data_uri.empty()) {
    return "<p class=\"no-snapshots\">Wall snapshots: " +
           EscapeHtml(w.note.empty() ? "maps not written" : w.note) + "</p>\n";
  }
  const proto::CalibrationResult& c = s.calibration;
  const std::string before = fmt::format(
      "rig's extrinsic (before): this wall's spread {:.1f} mm; map median surfel thickness "
      "{:.2f} mm",
      1e3 * w.spread_rig_m, 1e3 * c.map_sharpness_rig().median_thickness_m());
  const std::string after = fmt::format(
      "estimate (after): this wall's spread {:.1f} mm; map median surfel thickness {:.2f} mm",
      1e3 * w.spread_calibrated_m, 1e3 * c.map_sharpness_estimate().median_thickness_m());
  const double height_m = w.slab.top_m - w.slab.bottom_m;
  std::string out = fmt::format(
      "<div class=\"snapshots\">\n<p>The largest vertical planar surface of the calibrated map "
      "({} cells, {} points, centre {:.2f} {:.2f} {:.2f} m in frame a), the same slab of both "
      "maps: {:.1f} m along the wall, {:.2f} m across, {:.2f} m high; 1 pixel = {:.1f} mm, "
      "darker = more points (the same shading for both). A wrong extrinsic shows as a thick "
      "or doubled wall. Spread: the robust σ of the points' distance across the wall, "
      "1.4826 median |b − median b|.</p>\n<div class=\"snapshot-views\">\n<div>\n<h4>From above (along "
      "the wall left to right, across it bottom to top)</h4>\n",
      w.slab.cells, w.slab.points, w.slab.center.x(), w.slab.center.y(), w.slab.center.z(),
      w.slab.length_m, w.slab.depth_m, height_m,
      w.top_rig.width > 0 ? 1e3 * w.slab.length_m / w.top_rig.width : 0.0);
  out += SnapshotFigure(w.top_rig, "top rig", before);
  out += SnapshotFigure(w.top_calibrated, "top calibrated", after);
  out += "</div>\n<div>\n<h4>Looking along the wall<br>(across it left to right)</h4>\n"
         "<div class=\"side-views\">\n";
  out += SnapshotFigure(w.side_rig, "side rig", "before");
  out += SnapshotFigure(w.side_calibrated, "side calibrated", "after");
  out += "</div>\n</div>\n</div>\n</div>\n";
  return out;
}

// The export texts, each in its own block; collapsed unless `open`.
std::string ExportsBlock(const std::vector<PageExport>& exports, const std::string& note,
                         const std::string& calibration_link, bool open) {
  if (exports.empty()) {
    return "<p class=\"no-exports\">Exports: " + EscapeHtml(note.empty() ? "none" : note) +
           "</p>\n";
  }
  std::string out = fmt::format(
      "<details class=\"exports\"{}>\n<summary>Exports for FAST-LIO, LIO-SAM, URDF, tf, Kalibr "
      "(<code>tiltcal_export --calibration={} --format=NAME</code>; README.md, Using the "
      "result)</summary>\n",
      open ? " open" : "", EscapeHtml(ShellWord(calibration_link)));
  for (const PageExport& e : exports) {
    out += fmt::format("<h4>{0}</h4>\n<pre class=\"export\" data-format=\"{0}\">{1}</pre>\n",
                       EscapeHtml(e.format), EscapeHtml(e.text));
  }
  return out + "</details>\n";
}

std::string YesNo(bool value) { return value ? "yes" : "no"; }

// The joint value of tiltcal_dataset_calibration: extrinsic with σ, each
// sequence's consistency with it, the exports.
std::string DatasetSection(const DatasetPage& d) {
  const proto::CalibrationResult& c = d.calibration;
  const std::string verdict = VerdictName(c);
  std::string out = fmt::format(
      "<section class=\"dataset\" id=\"dataset\">\n<h2>Dataset calibration: <span "
      "class=\"verdict verdict-{0}\">{0}</span></h2>\n<p>One extrinsic from the sequences "
      "({1}, tiltcal_dataset_calibration): the value to use.</p>\n"
      "<ul class=\"reasons\">\n",
      verdict, LinkOrText(d.calibration_link));
  for (const std::string& reason : c.verdict_reasons()) {
    out += "<li>" + EscapeHtml(reason) + "</li>\n";
  }
  out += "</ul>\n" + ExtrinsicTable(c);
  out += "<h3>Sequences</h3>\n<table class=\"consistency\">\n<tr><th>sequence</th>"
         "<th>verdict</th><th>used</th><th>χ²</th><th>dof</th><th>limit</th>"
         "<th>consistent</th><th>largest disagreement / reason</th></tr>\n";
  for (const proto::DatasetSequence& q : c.sequences()) {
    out += fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.1f}</td><td>{}</td><td>{:.1f}</td>"
        "<td>{}</td><td>{}</td></tr>\n",
        EscapeHtml(q.name()),
        q.verdict() == proto::CalibrationResult::VERDICT_UNSET
            ? std::string("UNSET")
            : proto::CalibrationResult::Verdict_Name(q.verdict()),
        YesNo(q.used()), q.consistency_chi2(), q.consistency_dof(), q.consistency_limit(),
        YesNo(q.consistent()),
        EscapeHtml(q.reason().empty() ? q.disagreement() : q.reason()));
  }
  out += "</table>\n<h3>Exports</h3>\n" +
         ExportsBlock(d.exports, d.exports_note, d.calibration_link, true) + "</section>\n";
  return out;
}

std::string SequenceSection(const SequencePage& s) {
  const proto::CalibrationResult& c = s.calibration;
  const std::string verdict = VerdictName(c);
  std::string out = fmt::format(
      "<section class=\"sequence\" id=\"sequence-{0}\">\n<h2>{0}: <span class=\"verdict "
      "verdict-{1}\">{1}</span>{2}</h2>\n",
      EscapeHtml(s.name), verdict, s.set_aside ? " (set aside)" : "");
  out += "<ul class=\"reasons\">\n";
  for (const std::string& reason : c.verdict_reasons()) {
    out += "<li>" + EscapeHtml(reason) + "</li>\n";
  }
  out += "</ul>\n";
  // Where the start came from, how far /tf_static is (verdict_notes).
  if (c.verdict_notes_size() > 0) {
    out += "<ul class=\"notes\">\n";
    for (const std::string& note : c.verdict_notes()) {
      out += "<li>" + EscapeHtml(note) + "</li>\n";
    }
    out += "</ul>\n";
  }
  out += ExtrinsicTable(c) + "<h3>Map sharpness</h3>\n" + SharpnessTable(c) +
         SnapshotsBlock(s);
  out += "<h3>Normalised residuals</h3>\n<div class=\"histograms\">\n";
  for (const proto::ResidualStatistics& r : c.residual_statistics()) {
    out += ResidualHistogramSvg(r);
  }
  out += "</div>\n<h4>Over time</h4>\n<div class=\"time-series-plots\">\n";
  for (const proto::ResidualStatistics& r : c.residual_statistics()) out += ResidualTimeSvg(r);
  out += "</div>\n<h3>Exports</h3>\n" +
         ExportsBlock(s.exports, s.exports_note, s.calibration_link, false) +
         "<h3>Files</h3>\n" + FilesList(s) + "</section>\n";
  return out;
}

}  // namespace

std::string FormatHtml(const std::string& title, const Repeatability& repeatability,
                       const std::vector<SequencePage>& sequences, const DatasetPage* dataset,
                       const VerifyPage* verify) {
  std::string out = fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<title>{0}</title>\n<style>{1}</style>\n</head>\n<body>\n<h1>{0}</h1>\n",
      EscapeHtml(title.empty() ? "tiltcal report" : title), kStyle);
  if (dataset != nullptr) out += DatasetSection(*dataset);
  if (verify != nullptr) out += VerifySection(*verify);
  out += RepeatabilityTable(repeatability);
  for (const SequencePage& s : sequences) out += SequenceSection(s);
  out += "</body>\n</html>\n";
  return out;
}

}  // namespace tiltcal::report
