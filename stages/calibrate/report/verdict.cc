#include "stages/calibrate/report/verdict.h"

#include <cmath>
#include <vector>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "common/geometry/angles.h"
#include "common/io/eigen_proto.h"

namespace tiltcal::calibrate {
namespace {

using Reasons = std::vector<std::string>;

// Reasons that make the result SUSPECT, and those that make it WEAK.
struct Findings {
  Reasons suspect;
  Reasons weak;
};

void CheckTimeOffsetBound(const proto::CalibrationResult& r, const proto::VerdictParams& params,
                          Findings* f) {
  const double lower = r.time_offset_lower_bound_s();
  const double upper = r.time_offset_upper_bound_s();
  if (lower >= upper) return;  // tau was not estimated
  const double tau = r.time_offset_s();
  if (tau - lower > params.at_bound_tolerance_s() && upper - tau > params.at_bound_tolerance_s()) {
    return;
  }
  f->suspect.push_back(fmt::format(
      "time offset at a bound of the solve: tau {:.3f} ms, bounds [{:.3f}, {:.3f}] ms; the true "
      "offset may lie beyond it (CalibrateParams.time_offset_bound_s, "
      "init.time_offset_search_step_s)",
      tau * 1e3, lower * 1e3, upper * 1e3));
}

void CheckSolver(const proto::CalibrationResult& r, const proto::VerdictParams& params,
                 Findings* f) {
  for (const proto::ObservabilityDirection& d : r.observability()) {
    if (d.direction_size() == 0) {
      f->suspect.push_back("no covariance: " + d.description());
    }
  }
  if (params.require_convergence() && !r.solver().converged()) {
    f->suspect.push_back(fmt::format("the last solve did not converge: {} after {} iterations",
                                     r.solver().termination(), r.solver().iterations()));
  }
}

double MaxRms(const std::string& type, const proto::VerdictParams& params) {
  if (type == "gyro") return params.max_gyro_rms();
  if (type == "accel") return params.max_accel_rms();
  if (type == "lidar") return params.max_lidar_rms();
  return params.max_ground_rms();
}

void CheckResiduals(const proto::CalibrationResult& r, const proto::VerdictParams& params,
                    Findings* f) {
  for (const proto::ResidualStatistics& s : r.residual_statistics()) {
    const double limit = MaxRms(s.type(), params);
    if (s.rms() > limit) {
      f->suspect.push_back(fmt::format(
          "{} residuals far above their noise model: RMS {:.2f} sigma (limit {:.2f}), median "
          "|r| {:.2f} sigma over {} values",
          s.type(), s.rms(), limit, s.median_abs(), s.count()));
    }
  }
}

void CheckMap(const proto::CalibrationResult& r, const proto::VerdictParams& params,
              Findings* f) {
  if (!r.has_map_sharpness_estimate() || !r.has_map_sharpness_rig()) return;
  const proto::MapSharpness& est = r.map_sharpness_estimate();
  const proto::MapSharpness& rig = r.map_sharpness_rig();
  if (est.planar_surfels() == 0) {
    f->suspect.push_back("the LiDAR map built with the estimate has no planar surfel");
    return;
  }
  if (rig.planar_surfels() == 0) return;
  if (est.common_surfels() == 0) {
    // No voxel planar in both maps: no thickness to compare, and the map
    // that kept fewer planar surfels is the smeared one.
    if (est.planar_surfels() < rig.planar_surfels()) {
      f->suspect.push_back(fmt::format(
          "the LiDAR map is less sharp with the estimate than with the rig: no voxel is planar "
          "in both maps, and the estimate's has {} planar surfels against the rig's {}",
          est.planar_surfels(), rig.planar_surfels()));
    }
    return;
  }
  const double ratio = est.median_thickness_m() / rig.median_thickness_m();
  const std::string numbers = fmt::format(
      "over the {} voxels planar in both maps, median surfel thickness {:.2f} cm with the "
      "estimate vs {:.2f} cm with the rig ({} and {} planar surfels)",
      est.common_surfels(), est.median_thickness_m() * 100.0, rig.median_thickness_m() * 100.0,
      est.planar_surfels(), rig.planar_surfels());
  if (ratio > params.max_map_thickness_ratio()) {
    f->suspect.push_back("the LiDAR map is less sharp with the estimate than with the rig: " +
                         numbers);
  } else if (MovedFarFromRig(r, params) && ratio >= params.large_move_max_thickness_ratio()) {
    f->suspect.push_back("moved far from the rig but the LiDAR map is not sharper (" + numbers +
                         "): " + DescribeMoveFromRig(r));
  }
}

void CheckHandEye(const proto::CalibrationResult& r, const proto::VerdictParams& params,
                  Findings* f) {
  if (!r.hand_eye_used() ||
      r.hand_eye_disagreement_deg() <= params.max_hand_eye_disagreement_deg()) {
    return;
  }
  f->suspect.push_back(fmt::format(
      "hand-eye and final rotation disagree by {:.2f} deg (limit {:.2f} deg)",
      r.hand_eye_disagreement_deg(), params.max_hand_eye_disagreement_deg()));
}

void CheckStaticStart(const proto::CalibrationResult& r, const proto::VerdictParams& params,
                      Findings* f) {
  if (!params.require_static_start()) return;
  if (!r.static_start()) {
    f->suspect.push_back(
        "no static start: gyro bias and gravity were initialised while moving (a static "
        "second at the start, or an IMU in other units, e.g. g or deg/s?)");
  } else if (r.static_samples() < static_cast<int64_t>(params.min_static_samples())) {
    f->suspect.push_back(fmt::format("too few static samples: {} (at least {})",
                                     r.static_samples(), params.min_static_samples()));
  }
}

void CheckImuIntrinsics(const proto::CalibrationResult& r, Findings* f) {
  const proto::ImuIntrinsicsReport& k = r.imu_intrinsics();
  if (!k.found() || k.estimated()) return;
  const proto::ImuTriadEstimate& g = k.gyro();
  const proto::ImuTriadEstimate& a = k.accel();
  f->suspect.push_back(fmt::format(
      "the IMU's scale and axis errors show in the residuals but were held at zero "
      "(imu_intrinsics.mode {}): score {:.0f} over {} degrees of freedom; they point to gyroscope "
      "scale ({:.0f}, {:.0f}, {:.0f}) ppm, accelerometer scale ({:.0f}, {:.0f}, {:.0f}) ppm and "
      "misalignment ({:.2f}, {:.2f}, {:.2f}) deg; the extrinsic and tau absorb them: calibrate "
      "with imu_intrinsics.mode AUTO",
      k.mode(), k.score_chi2(), k.score_dof(), g.scale_ppm().x(), g.scale_ppm().y(),
      g.scale_ppm().z(), a.scale_ppm().x(), a.scale_ppm().y(), a.scale_ppm().z(),
      a.misalignment_deg().x(), a.misalignment_deg().y(), a.misalignment_deg().z()));
}

// The clock drift: with rho estimated (time_offset_drift.h) decode's finding
// is answered (a verdict note gives the rate and tau at both ends); rho at a
// bound of the final solve is SUSPECT, rho undetermined WEAK. Without it,
// decode's finding makes the single tau WEAK.
void CheckClockDrift(const proto::CalibrationResult& r, const proto::VerdictParams& params,
                     Findings* f) {
  const proto::TimeOffsetDriftReport& d = r.time_offset_drift();
  if (d.estimated()) {
    const double half_span_s = 0.5 * (d.end_time_s() - d.start_time_s());
    const double lower = d.rate_lower_bound_ppm();
    const double upper = d.rate_upper_bound_ppm();
    // at_bound_tolerance_s of tau at the scans' ends, in ppm.
    const double tolerance_ppm =
        half_span_s > 0.0 ? params.at_bound_tolerance_s() / half_span_s * 1e6 : 0.0;
    if (lower < upper && (d.rate_ppm() - lower <= tolerance_ppm ||
                          upper - d.rate_ppm() <= tolerance_ppm)) {
      f->suspect.push_back(fmt::format(
          "clock rate at a bound of the solve: {:+.1f} ppm, bounds [{:+.1f}, {:+.1f}] ppm; the "
          "true rate may lie beyond it (time_offset_drift.max_rate_ppm, "
          "outer_loop.time_offset_step_bound_s)",
          d.rate_ppm(), lower, upper));
    }
    if (d.weak()) {
      f->weak.push_back(fmt::format(
          "clock drift not determined by this sequence: the LiDAR clock runs {:+.1f} ± {:.1f} ppm "
          "against the IMU's, so tau is known to {:.2f} ms at the first scan and {:.2f} ms at the "
          "last (above observability.weak_time_offset_sigma_s){}",
          d.rate_ppm(), d.rate_sigma_ppm(), d.time_offset_start_sigma_s() * 1e3,
          d.time_offset_end_sigma_s() * 1e3,
          r.clock_drift().empty() ? "" : "; decode: " + r.clock_drift()));
    }
    return;
  }
  if (r.clock_drift().empty()) return;
  f->weak.push_back("τ is the offset the whole sequence fits best, not the one at every time: " +
                    r.clock_drift());
}

// Translation direction d (frame b): the rig's and the estimate's component.
std::string WeakTranslationReason(const proto::ObservabilityDirection& d,
                                  const proto::CalibrationResult& r) {
  const Eigen::Vector3d v(d.direction(3), d.direction(4), d.direction(5));
  const double rig_m = v.dot(ToEigen(r.rig_imu_from_lidar().translation()));
  const double est_m = v.dot(ToEigen(r.imu_from_lidar().translation()));
  if (r.has_starting_extrinsic() && !r.starting_extrinsic().translation_known()) {
    // No lever-arm guess: the prior is wide and at zero, so the value is the
    // data's, weakly.
    return fmt::format(
        "translation along b ({:.2f}, {:.2f}, {:.2f}) weakly determined by the motion (no "
        "lever-arm guess in the rig): {:.4f} m, sigma {:.4f} m; longer driving with turns "
        "both ways, or imu_from_lidar in the rig, determines it",
        v.x(), v.y(), v.z(), est_m, d.sigma());
  }
  return fmt::format(
      "translation along b ({:.2f}, {:.2f}, {:.2f}) taken from the rig (prior): {:.4f} m there "
      "(rig {:.4f} m), sigma {:.4f} m",
      v.x(), v.y(), v.z(), est_m, rig_m, d.sigma());
}

std::string WithoutWeakMark(std::string description) {
  const std::string mark = " -- WEAK";
  const size_t at = description.find(mark);
  if (at != std::string::npos) description.erase(at, mark.size());
  return description;
}

void CheckWeakDirections(const proto::CalibrationResult& r, Findings* f) {
  for (const proto::ObservabilityDirection& d : r.observability()) {
    if (!d.weak() || d.direction_size() != 7) continue;
    const bool translation =
        Eigen::Vector3d(d.direction(3), d.direction(4), d.direction(5)).norm() > 0.5;
    const bool rotation =
        Eigen::Vector3d(d.direction(0), d.direction(1), d.direction(2)).norm() > 0.5;
    if (translation && r.has_rig_imu_from_lidar()) {
      f->weak.push_back(WeakTranslationReason(d, r));
    } else if (rotation) {
      f->weak.push_back("weakly determined (sigma above observability.weak_rotation_sigma_deg): " +
                        WithoutWeakMark(d.description()));
    } else {
      f->weak.push_back("weakly determined: " + WithoutWeakMark(d.description()));
    }
  }
}

std::string FormatRigid(const proto::Rigid3& t) {
  const Eigen::Quaterniond q = ToEigen(t.rotation()).normalized();
  const Eigen::Vector3d rpy =
      geometry::RadToDeg(q.toRotationMatrix().eulerAngles(2, 1, 0).reverse());
  return fmt::format("q (w {:.4f}, x {:.4f}, y {:.4f}, z {:.4f}) [zyx {:.2f}, {:.2f}, {:.2f} "
                     "deg], r ({:.4f}, {:.4f}, {:.4f}) m",
                     q.w(), q.x(), q.y(), q.z(), rpy.z(), rpy.y(), rpy.x(),
                     t.translation().x(), t.translation().y(), t.translation().z());
}

}  // namespace

bool MovedFarFromRig(const proto::CalibrationResult& r, const proto::VerdictParams& params) {
  return r.rotation_from_rig_deg() > params.large_rotation_deg() ||
         r.translation_from_rig_m() > params.large_translation_m();
}

std::string DescribeMoveFromRig(const proto::CalibrationResult& result) {
  return fmt::format("moved {:.2f} deg and {:.3f} m from the rig: rig {}; estimate {}",
                     result.rotation_from_rig_deg(), result.translation_from_rig_m(),
                     FormatRigid(result.rig_imu_from_lidar()),
                     FormatRigid(result.imu_from_lidar()));
}

void DecideVerdict(const proto::VerdictParams& params, proto::CalibrationResult* result) {
  Findings f;
  CheckTimeOffsetBound(*result, params, &f);
  CheckSolver(*result, params, &f);
  CheckResiduals(*result, params, &f);
  CheckMap(*result, params, &f);
  CheckHandEye(*result, params, &f);
  CheckStaticStart(*result, params, &f);
  CheckImuIntrinsics(*result, &f);
  CheckClockDrift(*result, params, &f);
  CheckWeakDirections(*result, &f);
  result->clear_verdict_reasons();
  if (!f.suspect.empty()) {
    result->set_verdict(proto::CalibrationResult::SUSPECT);
  } else if (!f.weak.empty()) {
    result->set_verdict(proto::CalibrationResult::WEAK);
  } else {
    result->set_verdict(proto::CalibrationResult::OK);
  }
  for (const std::string& s : f.suspect) result->add_verdict_reasons(s);
  for (const std::string& s : f.weak) result->add_verdict_reasons(s);
}

std::string FormatVerdict(const proto::CalibrationResult& result,
                          const proto::VerdictParams& params) {
  std::string out = "verdict " + proto::CalibrationResult::Verdict_Name(result.verdict());
  for (const std::string& reason : result.verdict_reasons()) out += "\n  - " + reason;
  for (const std::string& note : result.verdict_notes()) out += "\n  note: " + note;
  if (MovedFarFromRig(result, params)) out += "\n  note: " + DescribeMoveFromRig(result);
  return out;
}

}  // namespace tiltcal::calibrate
