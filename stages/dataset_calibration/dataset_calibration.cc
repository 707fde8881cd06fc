#include "stages/dataset_calibration/dataset_calibration.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <tuple>

#include <fmt/format.h>

#include <Eigen/Core>

#include "common/calibration/calibration_checks.h"
#include "common/calibration/extrinsic_estimate.h"
#include "common/geometry/angles.h"
#include "common/geometry/extrinsic_fusion.h"
#include "common/io/eigen_proto.h"
#include "common/io/provenance.h"
#include "common/io/text_proto.h"
#include "stages/calibrate/report/covariance_report.h"

namespace tiltcal::dataset {
namespace {

using calibration::DescribeComponent;
using calibration::PriorInformation;
using calibration::ReasonRefused;
using calibration::ToEstimate;
using geometry::ExtrinsicEstimate;
using geometry::kDegPerRad;

int Dimension(const proto::DatasetCalibrationParams& params) {
  return params.time_offset_shared() ? 7 : 6;
}

// Why a sequence cannot be fused ("" when it can): left out by the user,
// refused (common/calibration/calibration_checks.h; the reason names the file), or SUSPECT.
std::string ReasonNotUsable(const SequenceCalibration& s,
                            const proto::DatasetCalibrationParams& params) {
  const auto& excluded = params.exclude_sequences();
  if (std::find(excluded.begin(), excluded.end(), s.name) != excluded.end()) {
    return "left out by exclude_sequences";
  }
  if (s.result.covariance_size() == 0) return "no covariance";
  const std::string refused = ReasonRefused(s.result, Dimension(params), params.input());
  if (!refused.empty()) return s.path + ": " + refused;
  switch (s.result.verdict()) {
    case proto::CalibrationResult::OK:
    case proto::CalibrationResult::WEAK:
      return "";
    case proto::CalibrationResult::SUSPECT:
      return "verdict SUSPECT";
    default:
      return fmt::format("{}: verdict {} is not OK, WEAK or SUSPECT", s.path,
                         static_cast<int>(s.result.verdict()));
  }
}

// The prior counted once: centred on the rig, the mean of the solves' own
// prior information (their axes differ slightly with each motion).
geometry::ExtrinsicPrior JointPrior(const std::vector<const proto::CalibrationResult*>& used,
                                    int n) {
  geometry::ExtrinsicPrior prior;
  prior.rest = Eigen::VectorXd::Zero(n - 3);
  prior.rest.head<3>() = ToEigen(used.front()->rig_imu_from_lidar()).translation;
  prior.information = Eigen::MatrixXd::Zero(n, n);
  for (const proto::CalibrationResult* r : used) {
    prior.information += PriorInformation(*r, n) / static_cast<double>(used.size());
  }
  return prior;
}

struct Fusion {
  std::vector<ExtrinsicEstimate> estimates;  // per sequence (empty rest: unusable)
  std::vector<bool> used;
  int usable = 0;  // used before the consistency exclusion
  geometry::FusedExtrinsic fused;
};

void FuseUsed(const std::vector<SequenceCalibration>& sequences, int n, Fusion* f) {
  std::vector<ExtrinsicEstimate> used_estimates;
  std::vector<const proto::CalibrationResult*> used_results;
  for (size_t i = 0; i < sequences.size(); ++i) {
    if (!f->used[i]) continue;
    used_estimates.push_back(f->estimates[i]);
    used_results.push_back(&sequences[i].result);
  }
  f->fused = geometry::FuseExtrinsics(used_estimates, JointPrior(used_results, n));
}

// With auto_exclude: leaves out the most inconsistent used sequence and fuses
// again while one is beyond the limit and more than min_sequences (and more
// than two: of two that disagree, neither is the better) remain.
void ExcludeInconsistent(const std::vector<SequenceCalibration>& sequences,
                         const proto::DatasetCalibrationParams& params, int n, Fusion* f,
                         std::vector<std::string>* reasons) {
  const auto& consistency = params.consistency();
  while (consistency.auto_exclude()) {
    const auto used_count = std::count(f->used.begin(), f->used.end(), true);
    if (used_count <= std::max<long>(consistency.min_sequences(), 2)) return;
    int worst = -1;
    double worst_ratio = 1.0;
    std::string why;
    for (size_t i = 0; i < sequences.size(); ++i) {
      if (!f->used[i]) continue;
      const geometry::ExtrinsicConsistency c = geometry::TestConsistency(f->estimates[i], f->fused);
      const double limit = geometry::ChiSquareUpperQuantile(c.dof, consistency.p_value());
      if (c.dof > 0 && c.chi2 / limit > worst_ratio) {
        worst_ratio = c.chi2 / limit;
        worst = static_cast<int>(i);
        why = fmt::format("inconsistent with the others: chi2 {:.1f} > {:.1f} ({} dof), {}",
                          c.chi2, limit, c.dof, DescribeComponent(c.worst_component, c.worst_z));
      }
    }
    if (worst < 0) return;
    f->used[worst] = false;
    (*reasons)[worst] = why;
    FuseUsed(sequences, n, f);
  }
}

void FillSequences(const std::vector<SequenceCalibration>& sequences,
                   const proto::DatasetCalibrationParams& params, const Fusion& f,
                   const std::vector<std::string>& reasons, proto::CalibrationResult* out) {
  for (size_t i = 0; i < sequences.size(); ++i) {
    const proto::CalibrationResult& r = sequences[i].result;
    proto::DatasetSequence* s = out->add_sequences();
    s->set_name(sequences[i].name);
    s->set_calibration(sequences[i].path);
    *s->mutable_imu_from_lidar() = r.imu_from_lidar();
    s->set_time_offset_s(r.time_offset_s());
    s->set_time_offset_sigma_s(r.time_offset_sigma_s());
    s->set_verdict(r.verdict());
    s->set_used(f.used[i]);
    s->set_reason(reasons[i]);
    if (f.estimates[i].rest.size() == 0) continue;
    const geometry::ExtrinsicConsistency c =
        geometry::TestConsistency(f.estimates[i], f.fused, f.used[i]);
    s->set_consistency_chi2(c.chi2);
    s->set_consistency_dof(c.dof);
    s->set_consistency_limit(
        c.dof > 0 ? geometry::ChiSquareUpperQuantile(c.dof, params.consistency().p_value()) : 0.0);
    s->set_consistent(c.chi2 <= s->consistency_limit());
    s->set_disagreement(DescribeComponent(c.worst_component, c.worst_z));
  }
}

// tau of the dataset without shared clocks: the information-weighted mean of
// the used sequences' tau; its variance the larger of the mean's and the
// sequences' spread (sample variance).
void WeightedTimeOffset(const std::vector<SequenceCalibration>& sequences, const Fusion& f,
                        double* tau_s, double* variance_s2) {
  double weight_sum = 0.0, weighted = 0.0;
  std::vector<double> taus;
  for (size_t i = 0; i < sequences.size(); ++i) {
    if (!f.used[i]) continue;
    const double sigma = std::max(sequences[i].result.time_offset_sigma_s(), 1e-9);
    weight_sum += 1.0 / (sigma * sigma);
    weighted += sequences[i].result.time_offset_s() / (sigma * sigma);
    taus.push_back(sequences[i].result.time_offset_s());
  }
  *tau_s = weighted / weight_sum;
  double spread = 0.0;
  for (double t : taus) spread += (t - *tau_s) * (t - *tau_s);
  if (taus.size() > 1) spread /= static_cast<double>(taus.size() - 1);
  *variance_s2 = std::max(1.0 / weight_sum, spread);
}

void FillResult(const std::vector<SequenceCalibration>& sequences,
                const proto::DatasetCalibrationParams& params, const Fusion& f,
                proto::CalibrationResult* out) {
  const int n = Dimension(params);
  Rigid3d extrinsic;
  extrinsic.rotation = f.fused.rotation;
  extrinsic.translation = f.fused.rest.head<3>();
  *out->mutable_imu_from_lidar() = ToProto(extrinsic);
  calibrate::Matrix7d covariance = calibrate::Matrix7d::Zero();
  covariance.topLeftCorner(n, n) = f.fused.covariance;
  if (n == 7) {
    out->set_time_offset_s(f.fused.rest[3]);
  } else {
    double tau_s = 0.0, variance_s2 = 0.0;
    WeightedTimeOffset(sequences, f, &tau_s, &variance_s2);
    out->set_time_offset_s(tau_s);
    covariance(6, 6) = variance_s2;
  }
  const proto::CalibrationResult* first = nullptr;
  for (size_t i = 0; i < sequences.size() && first == nullptr; ++i) {
    if (f.used[i]) first = &sequences[i].result;
  }
  calibrate::MotionAxis motion;
  motion.axis_b = ToEigen(first->motion_rotation_axis_b());
  if (motion.axis_b.norm() < 0.5) motion.axis_b = Eigen::Vector3d::UnitZ();
  calibrate::FillCovarianceReport(covariance, extrinsic.rotation.toRotationMatrix(), motion,
                                  params.observability(), out);
  *out->mutable_rig_imu_from_lidar() = first->rig_imu_from_lidar();
  const Rigid3d rig = ToEigen(first->rig_imu_from_lidar());
  out->set_rotation_from_rig_deg(
      Eigen::AngleAxisd(rig.rotation.conjugate() * extrinsic.rotation).angle() * kDegPerRad);
  out->set_translation_from_rig_m((extrinsic.translation - rig.translation).norm());
}

proto::CalibrationResult::Verdict Worse(proto::CalibrationResult::Verdict a,
                                        proto::CalibrationResult::Verdict b) {
  const auto rank = [](proto::CalibrationResult::Verdict v) {
    return v == proto::CalibrationResult::SUSPECT ? 2 : v == proto::CalibrationResult::WEAK ? 1 : 0;
  };
  return rank(a) >= rank(b) ? a : b;
}

// The used sequences that fail the consistency test (none could be left
// out): their chi2 against the limit and the largest angle and distance
// between two used extrinsics; "" when every used sequence is consistent.
std::string Disagreement(const proto::DatasetCalibrationParams& params,
                         const proto::CalibrationResult& out) {
  std::vector<const proto::DatasetSequence*> used;
  std::string failing;
  for (const proto::DatasetSequence& s : out.sequences()) {
    if (!s.used()) continue;
    used.push_back(&s);
    if (!s.consistent()) {
      failing += fmt::format("{}{} chi2 {:.1f} > {:.1f} ({})", failing.empty() ? "" : ", ",
                             s.name(), s.consistency_chi2(), s.consistency_limit(),
                             s.disagreement());
    }
  }
  if (failing.empty()) return "";
  double angle_deg = -1.0, distance_m = -1.0;
  std::string angle_pair, distance_pair;
  for (size_t i = 0; i < used.size(); ++i) {
    for (size_t j = i + 1; j < used.size(); ++j) {
      const Rigid3d a = ToEigen(used[i]->imu_from_lidar());
      const Rigid3d b = ToEigen(used[j]->imu_from_lidar());
      const double angle =
          Eigen::AngleAxisd(a.rotation.conjugate() * b.rotation).angle() * kDegPerRad;
      const double distance = (a.translation - b.translation).norm();
      const std::string pair = used[i]->name() + " and " + used[j]->name();
      if (angle > angle_deg) std::tie(angle_deg, angle_pair) = std::tie(angle, pair);
      if (distance > distance_m) std::tie(distance_m, distance_pair) = std::tie(distance, pair);
    }
  }
  return fmt::format(
      "the used sequences disagree and none can be left out ({} used, consistency.min_sequences "
      "{}, auto_exclude {}): {}; largest angle between two used extrinsics {:.3f} deg ({}), "
      "largest distance {:.4f} m ({})",
      used.size(), params.consistency().min_sequences(),
      params.consistency().auto_exclude() ? "true" : "false", failing, angle_deg, angle_pair,
      distance_m, distance_pair);
}

// With one usable sequence the dataset's result is that sequence's: its
// verdict (WEAK also when the dataset's observability thresholds see a weak
// direction) and its reasons. With two or more: SUSPECT when fewer than
// consistency.min_sequences are used, when a used sequence is inconsistent
// with the joint value, or when the joint solve did not converge; else WEAK
// or OK from the joint directions.
void DecideVerdict(const std::vector<SequenceCalibration>& sequences,
                   const proto::DatasetCalibrationParams& params, const Fusion& f,
                   proto::CalibrationResult* out) {
  int used = 0;
  const proto::CalibrationResult* single = nullptr;
  std::vector<std::string> notes;
  for (size_t i = 0; i < sequences.size(); ++i) {
    const proto::DatasetSequence& s = out->sequences(static_cast<int>(i));
    if (s.used()) {
      ++used;
      single = &sequences[i].result;
    } else {
      notes.push_back(fmt::format("left out {}: {}", s.name(), s.reason()));
    }
  }
  std::vector<std::string> reasons;
  for (const proto::ObservabilityDirection& d : out->observability()) {
    if (d.weak()) reasons.push_back("weakly determined: " + d.description());
  }
  proto::CalibrationResult::Verdict verdict =
      reasons.empty() ? proto::CalibrationResult::OK : proto::CalibrationResult::WEAK;
  if (f.usable == 1) {
    verdict = Worse(verdict, single->verdict());
    reasons.insert(reasons.begin(), "one sequence: no consistency check between sequences");
    for (const std::string& r : single->verdict_reasons()) {
      if (std::find(reasons.begin(), reasons.end(), r) == reasons.end()) reasons.push_back(r);
    }
  } else {
    std::vector<std::string> suspect;
    if (used < static_cast<int>(params.consistency().min_sequences())) {
      suspect.push_back(fmt::format("only {} sequence(s) used (consistency.min_sequences {})",
                                    used, params.consistency().min_sequences()));
    }
    const std::string disagreement = Disagreement(params, *out);
    if (!disagreement.empty()) suspect.push_back(disagreement);
    if (!f.fused.converged) {
      suspect.push_back(fmt::format("the joint solve did not converge in {} iterations",
                                    f.fused.iterations));
    }
    if (!suspect.empty()) verdict = proto::CalibrationResult::SUSPECT;
    reasons.insert(reasons.begin(), suspect.begin(), suspect.end());
  }
  out->set_verdict(verdict);
  out->clear_verdict_reasons();
  for (const std::string& r : reasons) out->add_verdict_reasons(r);
  for (const std::string& r : notes) out->add_verdict_reasons(r);
}

// Exit 0 or 3 only with finite numbers (the inputs are checked, so this
// holds; a failure here is an error, not a result).
Status CheckFinite(const proto::CalibrationResult& out) {
  const Rigid3d x = ToEigen(out.imu_from_lidar());
  bool finite = x.rotation.coeffs().allFinite() && x.translation.allFinite() &&
                std::isfinite(out.time_offset_s()) && std::isfinite(out.time_offset_sigma_s());
  for (double v : out.covariance()) finite = finite && std::isfinite(v);
  for (const proto::DatasetSequence& s : out.sequences()) {
    finite = finite && std::isfinite(s.consistency_chi2()) && std::isfinite(s.consistency_limit());
  }
  if (finite) return Status::Ok();
  return Status::Error("the joint solve gave non-finite values (extrinsic, tau or covariance)");
}

}  // namespace

Status CalibrateDataset(const std::vector<SequenceCalibration>& sequences,
                        const proto::DatasetCalibrationParams& params,
                        proto::CalibrationResult* out) {
  TILTCAL_RETURN_IF_ERROR(calibration::ValidateSequenceInputParams(params.input()));
  out->Clear();
  const int n = Dimension(params);
  Fusion f;
  f.estimates.resize(sequences.size());
  f.used.assign(sequences.size(), false);
  std::vector<std::string> reasons(sequences.size());
  std::string unusable;
  for (size_t i = 0; i < sequences.size(); ++i) {
    if (ReasonRefused(sequences[i].result, n, params.input()).empty()) {
      f.estimates[i] = ToEstimate(sequences[i].result, n);
    }
    reasons[i] = ReasonNotUsable(sequences[i], params);
    f.used[i] = reasons[i].empty();
    if (!f.used[i]) unusable += fmt::format("; {}: {}", sequences[i].name, reasons[i]);
  }
  f.usable = static_cast<int>(std::count(f.used.begin(), f.used.end(), true));
  if (f.usable == 0) {
    return Status::Error(fmt::format("no sequence can be used ({} read{})", sequences.size(),
                                     unusable));
  }
  FuseUsed(sequences, n, &f);
  ExcludeInconsistent(sequences, params, n, &f, &reasons);
  FillResult(sequences, params, f, out);
  FillSequences(sequences, params, f, reasons, out);
  DecideVerdict(sequences, params, f, out);
  return CheckFinite(*out);
}

namespace {

void LogTable(const proto::CalibrationResult& out, std::ostream* log) {
  if (log == nullptr) return;
  *log << fmt::format("{:<20} {:>8} {:>5} {:>16}  {}\n", "sequence", "verdict", "used",
                      "chi2 / limit", "largest difference from the joint value");
  for (const proto::DatasetSequence& s : out.sequences()) {
    *log << fmt::format("{:<20} {:>8} {:>5} {:>7.1f} / {:<6.1f}  {}{}\n", s.name(),
                        proto::CalibrationResult::Verdict_Name(s.verdict()), s.used() ? "yes" : "no",
                        s.consistency_chi2(), s.consistency_limit(), s.disagreement(),
                        s.reason().empty() ? "" : " (" + s.reason() + ")");
  }
  const Rigid3d x = ToEigen(out.imu_from_lidar());
  *log << fmt::format(
      "tiltcal_dataset_calibration: joint C_bl q (w {:.6f}, x {:.6f}, y {:.6f}, z {:.6f}), "
      "r_b^lb ({:.4f}, {:.4f}, {:.4f}) m; sigma rotation ({:.4f}, {:.4f}, {:.4f}) deg, "
      "translation ({:.2f}, {:.2f}, {:.2f}) mm; verdict {}\n",
      x.rotation.w(), x.rotation.x(), x.rotation.y(), x.rotation.z(), x.translation.x(),
      x.translation.y(), x.translation.z(), out.rotation_sigma_deg().x(),
      out.rotation_sigma_deg().y(), out.rotation_sigma_deg().z(),
      out.translation_sigma_m().x() * 1e3, out.translation_sigma_m().y() * 1e3,
      out.translation_sigma_m().z() * 1e3, proto::CalibrationResult::Verdict_Name(out.verdict()));
  for (const std::string& reason : out.verdict_reasons()) *log << "  - " << reason << "\n";
}

}  // namespace

Status Run(const DatasetCalibrationPaths& paths, const proto::DatasetCalibrationParams& params,
           std::ostream* log, proto::CalibrationResult* result) {
  if (paths.calibrations.empty()) return Status::Error("no calibration given");
  std::vector<SequenceCalibration> sequences(paths.calibrations.size());
  std::vector<InputPath> input_paths;
  for (size_t i = 0; i < paths.calibrations.size(); ++i) {
    sequences[i].path = paths.calibrations[i];
    sequences[i].name =
        std::filesystem::path(paths.calibrations[i]).parent_path().filename().string();
    TILTCAL_RETURN_IF_ERROR(ReadTextProto(paths.calibrations[i], &sequences[i].result));
    input_paths.push_back({"calibration", paths.calibrations[i]});
  }
  if (!paths.params.empty()) input_paths.push_back({"params", paths.params});
  proto::CalibrationResult& out = *result;
  TILTCAL_RETURN_IF_ERROR(CalibrateDataset(sequences, params, &out));
  *out.mutable_provenance() =
      MakeProvenance("tiltcal_dataset_calibration", params, input_paths, paths.command_line);
  TILTCAL_RETURN_IF_ERROR(WriteTextProto(paths.out, out));
  LogTable(out, log);
  return Status::Ok();
}

}  // namespace tiltcal::dataset
