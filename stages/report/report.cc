#include "stages/report/report.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "common/geometry/angles.h"
#include "common/geometry/euler_angles.h"
#include "common/geometry/rotation_statistics.h"
#include "common/geometry/so3.h"
#include "common/io/atomic_file.h"
#include "common/io/csv_field.h"
#include "common/io/eigen_proto.h"
#include "common/io/params.h"
#include "common/io/rig.h"
#include "common/io/text_proto.h"
#include "stages/report/report_page.h"

namespace tiltcal::report {

namespace {

using geometry::kDegPerRad;

Row MakeRow(const std::string& label, const proto::Rigid3& imu_from_lidar, double time_offset_s) {
  const Rigid3d extrinsic = ToEigen(imu_from_lidar);
  Row row;
  row.label = label;
  row.translation_cm = 100.0 * extrinsic.translation;
  row.euler123_deg =
      kDegPerRad * geometry::Euler123FromRotation(extrinsic.rotation.toRotationMatrix());
  row.time_offset_ms = 1e3 * time_offset_s;
  return row;
}

void AddErrors(const proto::SimulationTruth& truth, const proto::CalibrationResult& estimate,
               Row* row) {
  const Rigid3d est = ToEigen(estimate.imu_from_lidar());
  const Rigid3d tru = ToEigen(truth.imu_from_lidar());
  row->has_errors = true;
  row->rotation_error_deg =
      kDegPerRad * geometry::LogMatrix((tru.rotation.conjugate() * est.rotation).toRotationMatrix())
                      .norm();
  row->translation_error_cm = 100.0 * (est.translation - tru.translation);
  row->time_offset_error_ms = 1e3 * (estimate.time_offset_s() - truth.time_offset_s());
}

// The last component of a sequence directory ("out/run1/" -> "run1").
std::string SequenceName(const std::string& dir) {
  const std::filesystem::path path = std::filesystem::path(dir).lexically_normal();
  const std::string name = path.filename().string();
  return name.empty() ? path.parent_path().filename().string() : name;
}

std::string Fixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  return buffer;
}

// The sections of the page: every directory's calibration.txtpb or
// calibration.suspect.txtpb and its maps, linked relative to the page.
// `file` relative to the folder of the page `page`.
std::string RelativeToPage(const std::string& page, const std::string& file) {
  const std::filesystem::path page_dir =
      std::filesystem::absolute(page).lexically_normal().parent_path();
  return std::filesystem::absolute(file).lexically_normal().lexically_relative(page_dir).string();
}

// The maps' vertical in frame a: -g_a / |g_a| (z when the file has no g_a).
Eigen::Vector3d UpOf(const proto::CalibrationResult& c) {
  const Eigen::Vector3d g(c.gravity_in_world().x(), c.gravity_in_world().y(),
                          c.gravity_in_world().z());
  return g.norm() > 0 && g.allFinite() ? Eigen::Vector3d(-g.normalized())
                                       : Eigen::Vector3d::UnitZ();
}

Status ReadSequencePages(const ReportPaths& paths, const proto::ReportParams& params,
                         std::vector<SequencePage>* pages) {
  auto link = [&](const std::string& file) {
    return std::filesystem::exists(file) ? RelativeToPage(paths.out_html, file) : std::string();
  };
  for (const std::string& dir : paths.sequence_dirs) {
    SequencePage page;
    page.name = SequenceName(dir);
    page.set_aside = !std::filesystem::exists(dir + "/calibration.txtpb");
    const std::string file =
        dir + (page.set_aside ? "/calibration.suspect.txtpb" : "/calibration.txtpb");
    TILTCAL_RETURN_IF_ERROR(ReadTextProto(file, &page.calibration));
    page.calibration_link = link(file);
    page.map_rig_link = link(dir + "/map_rig.pcd");
    page.map_calibrated_link = link(dir + "/map_calibrated.pcd");
    if (!page.map_rig_link.empty() && !page.map_calibrated_link.empty()) {
      TILTCAL_RETURN_IF_ERROR(MakeWallSnapshots(dir + "/map_rig.pcd", dir + "/map_calibrated.pcd",
                                                UpOf(page.calibration), params.wall_snapshot(),
                                                &page.snapshots));
    } else {
      page.snapshots.note = "the maps were not written (tiltcal_calibrate --out_map_rig, "
                            "--out_map_calibrated)";
    }
    page.exports = MakePageExports(page.calibration, file, &page.exports_note);
    pages->push_back(std::move(page));
  }
  return Status::Ok();
}

std::string Pad(const std::string& text, size_t width) {
  return text.size() >= width ? text + " " : std::string(width - text.size(), ' ') + text;
}

}  // namespace

Repeatability ComputeRepeatability(const std::vector<SequenceResult>& results,
                                   const proto::Rig* rig) {
  Repeatability out;
  std::vector<Eigen::Matrix3d> rotations;
  std::vector<Eigen::Vector3d> translations, others, errors;
  bool all_have_errors = !results.empty();
  for (const SequenceResult& result : results) {
    Row row = MakeRow(result.name, result.calibration.imu_from_lidar(),
                      result.calibration.time_offset_s());
    if (result.truth) AddErrors(*result.truth, result.calibration, &row);
    all_have_errors = all_have_errors && row.has_errors;
    rotations.push_back(ToEigen(result.calibration.imu_from_lidar()).rotation.toRotationMatrix());
    translations.push_back(row.translation_cm);
    others.push_back({row.time_offset_ms, row.rotation_error_deg, row.time_offset_error_ms});
    errors.push_back(row.translation_error_cm);
    if (result.calibration.verdict() != proto::CalibrationResult::VERDICT_UNSET) {
      row.verdict = proto::CalibrationResult::Verdict_Name(result.calibration.verdict());
    }
    out.sequences.push_back(row);
  }
  out.mean.label = "mean";
  out.sigma.label = "sigma";
  if (!results.empty()) {
    const auto rotation = geometry::ComputeRotationStatistics(rotations);
    const auto translation = geometry::ComputeVectorStatistics(translations);
    const auto other = geometry::ComputeVectorStatistics(others);
    const auto error = geometry::ComputeVectorStatistics(errors);
    out.rotation_mean_converged = rotation.converged;
    out.mean.euler123_deg = kDegPerRad * geometry::Euler123FromRotation(rotation.mean);
    out.sigma.euler123_deg = kDegPerRad * rotation.sigma;
    out.mean.translation_cm = translation.mean;
    out.sigma.translation_cm = translation.sigma;
    out.mean.time_offset_ms = other.mean.x();
    out.sigma.time_offset_ms = other.sigma.x();
    if (all_have_errors) {
      out.mean.has_errors = out.sigma.has_errors = true;
      out.mean.rotation_error_deg = other.mean.y();
      out.sigma.rotation_error_deg = other.sigma.y();
      out.mean.time_offset_error_ms = other.mean.z();
      out.sigma.time_offset_error_ms = other.sigma.z();
      out.mean.translation_error_cm = error.mean;
      out.sigma.translation_error_cm = error.sigma;
    }
  }
  if (rig != nullptr && HasValidRotation(rig->imu_from_lidar())) {
    out.measured = MakeRow("measured", rig->imu_from_lidar(), 0.0);
  }
  return out;
}

void AddDatasetCalibration(const proto::CalibrationResult& dataset,
                           const std::vector<SequenceResult>& results, Repeatability* r) {
  Row joint = MakeRow("joint", dataset.imu_from_lidar(), dataset.time_offset_s());
  for (const SequenceResult& result : results) {
    if (!result.truth) continue;
    AddErrors(*result.truth, dataset, &joint);
    break;
  }
  if (dataset.verdict() != proto::CalibrationResult::VERDICT_UNSET) {
    joint.verdict = proto::CalibrationResult::Verdict_Name(dataset.verdict());
  }
  r->joint = joint;
  for (Row& row : r->sequences) {
    for (const proto::DatasetSequence& s : dataset.sequences()) {
      if (s.name() != row.label) continue;
      row.consistency = "chi2 " + Fixed(s.consistency_chi2(), 1) + " / " +
                        Fixed(s.consistency_limit(), 1) + (s.used() ? "" : " left out");
    }
  }
}

std::string FormatTable(const Repeatability& r, const std::string& title) {
  const bool errors = r.mean.has_errors ||
                      std::any_of(r.sequences.begin(), r.sequences.end(),
                                  [](const Row& row) { return row.has_errors; });
  size_t label_width = 10;
  for (const Row& row : r.sequences) label_width = std::max(label_width, row.label.size() + 2);
  std::string out = title.empty() ? "" : title + "\n";
  out += "extrinsic imu_from_lidar: r_b^{lb} in cm, C_bl as 1-2-3 Euler angles in deg "
         "(sigma row: per-component sigma of the SO(3) deviations, deg); tau in ms\n";
  std::string header = Pad("sequence", label_width) + Pad("r_x", 9) + Pad("r_y", 9) +
                       Pad("r_z", 9) + Pad("C_1", 10) + Pad("C_2", 10) + Pad("C_3", 10) +
                       Pad("tau", 9);
  if (errors) {
    header += "   |" + Pad("rot err", 9) + Pad("x err", 8) + Pad("y err", 8) + Pad("z err", 8) +
              Pad("tau err", 9);
  }
  header += "  verdict";
  const bool consistency = r.joint.has_value();
  if (consistency) header += "   consistency with the joint value";
  out += header + "\n" + std::string(header.size(), '-') + "\n";
  auto line = [&](const Row& row) {
    std::string text = Pad(row.label, label_width);
    for (int i = 0; i < 3; ++i) text += Pad(Fixed(row.translation_cm[i], 2), 9);
    for (int i = 0; i < 3; ++i) text += Pad(Fixed(row.euler123_deg[i], 3), 10);
    text += Pad(Fixed(row.time_offset_ms, 3), 9);
    if (errors && row.has_errors) {
      text += "   |" + Pad(Fixed(row.rotation_error_deg, 3), 9);
      for (int i = 0; i < 3; ++i) text += Pad(Fixed(row.translation_error_cm[i], 2), 8);
      text += Pad(Fixed(row.time_offset_error_ms, 3), 9);
    } else if (errors && !row.verdict.empty()) {
      text += "   |" + std::string(9 + 3 * 8 + 9, ' ');
    }
    std::string verdict = row.verdict;
    if (!row.consistency.empty()) verdict.resize(std::max<size_t>(verdict.size(), 7), ' ');
    if (!verdict.empty()) text += "  " + verdict;
    if (!row.consistency.empty()) text += "   " + row.consistency;
    out += text + "\n";
  };
  for (const Row& row : r.sequences) line(row);
  out += std::string(header.size(), '-') + "\n";
  line(r.mean);
  line(r.sigma);
  if (r.measured) line(*r.measured);
  if (r.joint) line(*r.joint);
  if (!r.rotation_mean_converged) out += "warning: the SO(3) mean did not converge\n";
  for (const std::string& name : r.suspect_set_aside) {
    out += "suspect, set aside (read its verdict_reasons): " + name + "\n";
  }
  return out;
}

std::string FormatCsv(const Repeatability& r) {
  std::string out =
      "sequence,r_x_cm,r_y_cm,r_z_cm,euler_1_deg,euler_2_deg,euler_3_deg,time_offset_ms,"
      "rotation_error_deg,error_x_cm,error_y_cm,error_z_cm,time_offset_error_ms,verdict\n";
  auto line = [&](const Row& row) {
    char buffer[512];
    out += CsvField(row.label);
    std::snprintf(buffer, sizeof(buffer), ",%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g",
                  row.translation_cm.x(), row.translation_cm.y(),
                  row.translation_cm.z(), row.euler123_deg.x(), row.euler123_deg.y(),
                  row.euler123_deg.z(), row.time_offset_ms);
    out += buffer;
    if (row.has_errors) {
      std::snprintf(buffer, sizeof(buffer), ",%.17g,%.17g,%.17g,%.17g,%.17g",
                    row.rotation_error_deg, row.translation_error_cm.x(),
                    row.translation_error_cm.y(), row.translation_error_cm.z(),
                    row.time_offset_error_ms);
      out += buffer;
    } else {
      out += ",,,,,";
    }
    out += "," + CsvField(row.verdict) + "\n";
  };
  for (const Row& row : r.sequences) line(row);
  line(r.mean);
  line(r.sigma);
  if (r.measured) line(*r.measured);
  return out;
}

namespace {

// Reads a calibration or a truth file whose extrinsic and time offset go
// into the statistics: a file without them, or with a NaN, Inf or a
// non-unit quaternion, is an error naming the file and the field (it would
// turn the mean and σ into garbage).
template <typename Answer>
Status ReadCalibrationAnswer(const std::string& path, Answer* answer) {
  TILTCAL_RETURN_IF_ERROR(ReadTextProto(path, answer));
  TILTCAL_RETURN_IF_ERROR(ValidateImuFromLidar(answer->has_imu_from_lidar(),
                                               answer->mutable_imu_from_lidar(), "imu_from_lidar")
                              .WithContext(path));
  if (!std::isfinite(answer->time_offset_s())) {
    return Status::Error(path + ": time_offset_s is not finite");
  }
  return Status::Ok();
}

}  // namespace

Status Run(const ReportPaths& paths, const proto::ReportParams& params, std::ostream* log) {
  if (paths.sequence_dirs.empty()) {
    return Status::Error("no sequence directories given");
  }
  TILTCAL_RETURN_IF_ERROR(ValidateAgainstSchema(params).WithContext("report params"));
  TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out));
  if (!paths.out_csv.empty()) TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out_csv));
  std::vector<SequenceResult> results;
  std::vector<std::string> suspect_set_aside;
  for (const std::string& dir : paths.sequence_dirs) {
    SequenceResult result;
    result.name = SequenceName(dir);
    if (!std::filesystem::exists(dir + "/calibration.txtpb") &&
        std::filesystem::exists(dir + "/calibration.suspect.txtpb")) {
      suspect_set_aside.push_back(dir + "/calibration.suspect.txtpb");
      continue;
    }
    TILTCAL_RETURN_IF_ERROR(ReadCalibrationAnswer(dir + "/calibration.txtpb", &result.calibration));
    if (std::filesystem::exists(dir + "/truth.txtpb")) {
      result.truth.emplace();
      TILTCAL_RETURN_IF_ERROR(ReadCalibrationAnswer(dir + "/truth.txtpb", &*result.truth));
    }
    results.push_back(std::move(result));
  }
  proto::Rig rig;
  if (!paths.rig.empty()) TILTCAL_RETURN_IF_ERROR(LoadRig(paths.rig, &rig));
  if (results.empty()) {
    return Status::Error("no usable calibration: every sequence was set aside as SUSPECT (" +
                         suspect_set_aside.front() + " ...)");
  }
  Repeatability repeatability = ComputeRepeatability(results, paths.rig.empty() ? nullptr : &rig);
  repeatability.suspect_set_aside = suspect_set_aside;
  std::optional<DatasetPage> dataset;
  if (!paths.dataset_calibration.empty()) {
    dataset.emplace();
    TILTCAL_RETURN_IF_ERROR(
        ReadCalibrationAnswer(paths.dataset_calibration, &dataset->calibration));
    AddDatasetCalibration(dataset->calibration, results, &repeatability);
  }
  std::optional<VerifyPage> verify;
  if (!paths.verify.empty()) {
    verify.emplace();
    TILTCAL_RETURN_IF_ERROR(ReadTextProto(paths.verify, &verify->result));
    if (!paths.out_html.empty()) verify->link = RelativeToPage(paths.out_html, paths.verify);
  }
  // Everything is read and computed before the first output is written.
  std::string html;
  if (!paths.out_html.empty()) {
    TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out_html));
    std::vector<SequencePage> pages;
    TILTCAL_RETURN_IF_ERROR(ReadSequencePages(paths, params, &pages));
    if (dataset) {
      dataset->calibration_link = RelativeToPage(paths.out_html, paths.dataset_calibration);
      dataset->exports = MakePageExports(dataset->calibration, paths.dataset_calibration,
                                         &dataset->exports_note);
    }
    html = FormatHtml(paths.title, repeatability, pages, dataset ? &*dataset : nullptr,
                      verify ? &*verify : nullptr);
  }
  const std::string table = FormatTable(repeatability, paths.title);
  TILTCAL_RETURN_IF_ERROR(WriteFileAtomically(paths.out, table));
  if (!paths.out_csv.empty()) {
    TILTCAL_RETURN_IF_ERROR(WriteFileAtomically(paths.out_csv, FormatCsv(repeatability)));
  }
  if (!paths.out_html.empty()) TILTCAL_RETURN_IF_ERROR(WriteFileAtomically(paths.out_html, html));
  if (log != nullptr) *log << table;
  return Status::Ok();
}

}  // namespace tiltcal::report
