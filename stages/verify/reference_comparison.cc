#include "stages/verify/reference_comparison.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include <Eigen/Core>

#include "common/calibration/calibration_checks.h"
#include "common/calibration/extrinsic_estimate.h"
#include "common/geometry/angles.h"
#include "common/geometry/extrinsic_fusion.h"
#include "common/geometry/so3.h"
#include "common/io/eigen_proto.h"
#include "common/linear_algebra/dense_decompositions.h"

namespace tiltcal::verify {
namespace {

using geometry::kDegPerRad;
// Eigenvalues of W below this fraction of the group's largest count as no
// information (the difference's degrees of freedom leave them out).
constexpr double kRelativeEigenvalueFloor = 1e-12;

using Verdict = proto::VerifyResult::Verdict;

// One block of the tangent space: rotation (rad), translation (m) or tau (s),
// shown in deg, mm, ms.
struct Group {
  const char* name;
  int start;
  int size;
  double unit_scale;  // to the shown unit
  const char* unit;
  double detectable;  // params.detectable, in the tangent units
};

std::vector<Group> Groups(const proto::VerifyParams& params, int n) {
  std::vector<Group> groups = {
      {"rotation", 0, 3, kDegPerRad, "deg", params.detectable().rotation_deg() / kDegPerRad},
      {"translation", 3, 3, 1e3, "mm", params.detectable().translation_m()}};
  if (n == 7) groups.push_back({"tau", 6, 1, 1e3, "ms", params.detectable().time_offset_s()});
  return groups;
}

Eigen::MatrixXd Symmetric(const Eigen::MatrixXd& m) { return 0.5 * (m + m.transpose()); }

// Eigen-decomposition with the eigenvalues below the floor (relative to the
// largest) set to zero; the count of the rest in *rank.
linear_algebra::SymmetricEigen Decompose(const Eigen::MatrixXd& m, Eigen::VectorXd* values,
                                         int* rank) {
  linear_algebra::SymmetricEigen eig = linear_algebra::DecomposeSymmetric(Symmetric(m));
  *values = eig.values;
  const double largest = std::max(values->maxCoeff(), 0.0);
  *rank = 0;
  for (int i = 0; i < values->size(); ++i) {
    if ((*values)[i] > kRelativeEigenvalueFloor * largest && largest > 0.0) {
      ++*rank;
    } else {
      (*values)[i] = 0.0;
    }
  }
  return eig;
}

Eigen::MatrixXd PseudoInverse(const Eigen::MatrixXd& m) {
  Eigen::VectorXd values;
  int rank = 0;
  const auto eig = Decompose(m, &values, &rank);
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(values.size());
  for (int i = 0; i < values.size(); ++i) {
    if (values[i] > 0.0) inverse[i] = 1.0 / values[i];
  }
  return eig.vectors * inverse.asDiagonal() * eig.vectors.transpose();
}

// " b (x, y, z)" of a unit vector; an axis (signed_direction false: an
// eigenvector, whose sign means nothing) with its largest component positive.
std::string Direction(const Eigen::VectorXd& u, bool signed_direction = false) {
  if (u.size() == 1) return "";
  Eigen::Index largest = 0;
  u.cwiseAbs().maxCoeff(&largest);
  const Eigen::VectorXd v = !signed_direction && u[largest] < 0.0 ? Eigen::VectorXd(-u) : u;
  // Rounded to the digits shown, + 0.0 turning -0 into 0.
  const auto shown = [](double x) { return std::round(100.0 * x) / 100.0 + 0.0; };
  return fmt::format(" b ({:.2f}, {:.2f}, {:.2f})", shown(v[0]), shown(v[1]), shown(v[2]));
}

// "rotation 0.982 deg about b (0.01, -0.02, 1.00), 12.3 sigma".
std::string DescribeDifference(const Group& g, const Eigen::VectorXd& d_g, double sigma) {
  const double size = d_g.norm() * g.unit_scale;
  if (g.size == 1) {
    return fmt::format("{} {:+.3f} {}, {:.1f} sigma", g.name, d_g[0] * g.unit_scale, g.unit,
                       sigma);
  }
  const char* preposition = g.start == 0 ? "about" : "along";
  if (d_g.norm() == 0.0) return fmt::format("{} 0 {}, {:.1f} sigma", g.name, g.unit, sigma);
  return fmt::format("{} {:.{}f} {} {}{}, {:.1f} sigma", g.name, size, g.start == 3 ? 1 : 3,
                     g.unit, preposition, Direction(d_g.normalized(), true), sigma);
}

// The smallest move along unit u the test detects (tangent units); +inf when
// W holds no information along u.
double SmallestDetected(const Eigen::MatrixXd& w_gg, const Eigen::VectorXd& u, double limit,
                        double largest_eigenvalue) {
  const double information = u.dot(w_gg * u);
  if (!(information > kRelativeEigenvalueFloor * largest_eigenvalue) ||
      !(largest_eigenvalue > 0.0)) {
    return std::numeric_limits<double>::infinity();
  }
  return std::sqrt(limit / information);
}

void SetCannotTell(const std::string& reason, proto::SequenceVerification* out) {
  out->set_verdict(proto::VerifyResult::CANNOT_TELL);
  out->add_reasons(reason);
}

// The difference of the estimate from the reference in frame b and the
// weight of the test: W = (I + Lambda P_ref)^-1 Lambda, Lambda the data's
// information; chi2 = d^T W d against the quantile of W's rank.
struct Comparison {
  Eigen::VectorXd d;
  Eigen::MatrixXd w;
  Eigen::MatrixXd s;       // W^+
  Eigen::VectorXd values;  // W's eigenvalues (Decompose)
  int rank = 0;
  double chi2 = 0.0;
  double limit = 0.0;
};

// False when the calibration holds no information about the extrinsic
// (rank 0); then only d, w, values and rank are set.
bool Compare(const geometry::ExtrinsicEstimate& est, const geometry::ExtrinsicEstimate& ref,
             int n, double p_value, Comparison* c) {
  // Into frame b: rotation rows and columns turned by C_ref.
  Eigen::MatrixXd to_b = Eigen::MatrixXd::Identity(n, n);
  to_b.topLeftCorner<3, 3>() = ref.rotation.toRotationMatrix();
  Eigen::VectorXd d(n);
  d.head<3>() = geometry::BoxMinus(est.rotation, ref.rotation);
  d.tail(n - 3) = est.rest - ref.rest;
  c->d = to_b * d;
  // The data's information: the solve's prior removed, rounding below zero clipped.
  const auto data = Decompose(linear_algebra::Inverse(est.covariance) - est.prior_information,
                              &c->values, &c->rank);
  const Eigen::MatrixXd lambda_l = data.vectors * c->values.asDiagonal() * data.vectors.transpose();
  const Eigen::MatrixXd lambda = to_b * lambda_l * to_b.transpose();
  const Eigen::MatrixXd p_ref = to_b * ref.covariance * to_b.transpose();
  c->w = Symmetric(
      linear_algebra::SolveByLu(Eigen::MatrixXd::Identity(n, n) + lambda * p_ref, lambda));
  Decompose(c->w, &c->values, &c->rank);
  if (c->rank == 0) return false;
  c->chi2 = c->d.dot(c->w * c->d);
  c->limit = geometry::ChiSquareUpperQuantile(c->rank, p_value);
  c->s = PseudoInverse(c->w);
  return true;
}

// What the groups (rotation, translation, time offset) give the verdict:
// (sigma, description) of those that moved and of all, and per group the
// smallest move detected or why none is.
struct GroupFindings {
  std::vector<std::pair<double, std::string>> moved, largest;
  std::vector<std::string> undecided;
  std::vector<std::string> detected;
};

// The difference of group `g`, its sigma and the smallest move of it the
// check detects (along each axis of b and along the weakest direction).
void CompareGroup(const Group& g, const Comparison& c, double p_value,
                  proto::SequenceVerification* out, GroupFindings* findings) {
  const Eigen::VectorXd d_g = c.d.segment(g.start, g.size);
  const Eigen::MatrixXd s_gg = c.s.block(g.start, g.start, g.size, g.size);
  Eigen::VectorXd group_values;
  int group_rank = 0;
  Decompose(s_gg, &group_values, &group_rank);
  const double group_chi2 = d_g.dot(PseudoInverse(s_gg) * d_g);
  const double sigma = std::sqrt(std::max(group_chi2, 0.0));
  const std::string description = DescribeDifference(g, d_g, sigma);
  if (group_rank > 0 && group_chi2 > geometry::ChiSquareUpperQuantile(group_rank, p_value)) {
    findings->moved.emplace_back(sigma, description);
  }
  findings->largest.emplace_back(sigma, description);

  // Detectability: along each axis of b and along the weakest direction.
  const Eigen::MatrixXd w_gg = c.w.block(g.start, g.start, g.size, g.size);
  const linear_algebra::SymmetricEigen eig = linear_algebra::DecomposeSymmetric(w_gg);
  const double top = std::max(c.values.maxCoeff(), 0.0);
  Eigen::Vector3d axes = Eigen::Vector3d::Zero();
  for (int k = 0; k < g.size; ++k) {
    const double m = SmallestDetected(w_gg, Eigen::VectorXd::Unit(g.size, k), c.limit, top);
    axes[k] = std::isfinite(m) ? m : 0.0;
  }
  const Eigen::VectorXd weakest = eig.vectors.col(0);
  const double weakest_m = SmallestDetected(w_gg, weakest, c.limit, top);
  if (g.start == 0) {
    *out->mutable_rotation_difference_deg() = ToProto(Eigen::Vector3d(d_g * kDegPerRad));
    out->set_rotation_difference_sigma(sigma);
    *out->mutable_detectable_rotation_deg() = ToProto(Eigen::Vector3d(axes * kDegPerRad));
  } else if (g.start == 3) {
    *out->mutable_translation_difference_m() = ToProto(Eigen::Vector3d(d_g));
    out->set_translation_difference_sigma(sigma);
    *out->mutable_detectable_translation_m() = ToProto(axes);
  } else {
    out->set_time_offset_difference_s(d_g[0]);
    out->set_time_offset_difference_sigma(sigma);
    out->set_detectable_time_offset_s(axes[0]);
  }
  // "rotation about b (…)", "translation along b (…)", "tau change".
  const std::string what =
      g.size == 1 ? std::string(g.name) + " change"
                  : fmt::format("{} {}{}", g.name, g.start == 0 ? "about" : "along",
                                Direction(weakest));
  if (!std::isfinite(weakest_m)) {
    findings->undecided.push_back(fmt::format(
        "no {} is detected, whatever its size (the sequence holds no information about it)",
        what));
  } else if (weakest_m > g.detectable) {
    findings->undecided.push_back(fmt::format(
        "a {} below {:.3g} {} goes unnoticed (the check must notice {:.3g} {})", what,
        weakest_m * g.unit_scale, g.unit, g.detectable * g.unit_scale, g.unit));
  } else {
    findings->detected.push_back(
        fmt::format("{} {:.3g} {}", g.name, weakest_m * g.unit_scale, g.unit));
  }
}

// MOVED when chi2 is above its limit, else CANNOT_TELL while a group's
// detectable move is too large, else HOLDS; with the reasons.
void SetVerdict(const Comparison& c, GroupFindings* f, proto::SequenceVerification* out) {
  const auto by_sigma = [](const auto& a, const auto& b) { return a.first > b.first; };
  std::sort(f->moved.begin(), f->moved.end(), by_sigma);
  std::sort(f->largest.begin(), f->largest.end(), by_sigma);
  const std::string test = fmt::format("chi2 {:.1f} {} {:.1f} ({} dof)", c.chi2,
                                       c.chi2 > c.limit ? ">" : "<=", c.limit, c.rank);
  if (c.chi2 > c.limit) {
    out->set_verdict(proto::VerifyResult::MOVED);
    out->add_reasons("moved: " + test);
    if (f->moved.empty()) f->moved.push_back(f->largest.front());
    for (const auto& m : f->moved) out->add_reasons("moved: " + m.second);
  } else if (!f->undecided.empty()) {
    out->set_verdict(proto::VerifyResult::CANNOT_TELL);
    for (const std::string& u : f->undecided) out->add_reasons("cannot tell: " + u);
    out->add_reasons("no move seen: " + test + ", largest difference " +
                     f->largest.front().second);
  } else {
    out->set_verdict(proto::VerifyResult::HOLDS);
    std::string smallest;
    for (const std::string& m : f->detected) smallest += (smallest.empty() ? "" : ", ") + m;
    out->add_reasons("holds: " + test + ", largest difference " + f->largest.front().second +
                     "; the smallest moves it notices: " + smallest);
  }
}

}  // namespace

void CompareWithReference(const proto::CalibrationResult& estimate,
                          const proto::CalibrationResult& reference,
                          const proto::VerifyParams& params, proto::SequenceVerification* out) {
  out->set_calibration_verdict(estimate.verdict());
  *out->mutable_imu_from_lidar() = estimate.imu_from_lidar();
  out->set_time_offset_s(estimate.time_offset_s());
  if (estimate.verdict() == proto::CalibrationResult::SUSPECT) {
    std::string reasons;
    for (const std::string& r : estimate.verdict_reasons()) reasons += (reasons.empty() ? "" : "; ") + r;
    SetCannotTell("the sequence's calibration is SUSPECT: " + reasons, out);
    return;
  }
  const int n = params.compare_time_offset() ? 7 : 6;
  const std::string refused = calibration::ReasonRefused(estimate, n, params.input());
  if (!refused.empty()) {
    SetCannotTell("the sequence's calibration cannot be compared: " + refused, out);
    return;
  }
  const geometry::ExtrinsicEstimate est = calibration::ToEstimate(estimate, n);
  const geometry::ExtrinsicEstimate ref = calibration::ToEstimate(reference, n);
  Comparison c;
  if (!Compare(est, ref, n, params.p_value(), &c)) {
    SetCannotTell("the sequence's calibration holds no information about the extrinsic", out);
    return;
  }
  out->set_chi2(c.chi2);
  out->set_dof(c.rank);
  out->set_limit(c.limit);
  GroupFindings findings;
  for (const Group& g : Groups(params, n)) CompareGroup(g, c, params.p_value(), out, &findings);
  SetVerdict(c, &findings, out);
}

void DecideDatasetVerdict(proto::VerifyResult* result) {
  std::vector<std::string> moved, holds, cannot_tell;
  for (const proto::SequenceVerification& s : result->sequences()) {
    switch (s.verdict()) {
      case proto::VerifyResult::MOVED:
        moved.push_back(s.name());
        break;
      case proto::VerifyResult::HOLDS:
        holds.push_back(s.name());
        break;
      default:
        cannot_tell.push_back(s.name());
    }
  }
  const auto join = [](const std::vector<std::string>& names) {
    std::string out;
    for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
    return out;
  };
  result->clear_verdict_reasons();
  Verdict verdict = proto::VerifyResult::CANNOT_TELL;
  if (!moved.empty()) {
    verdict = proto::VerifyResult::MOVED;
    for (const proto::SequenceVerification& s : result->sequences()) {
      if (s.verdict() != proto::VerifyResult::MOVED) continue;
      for (const std::string& r : s.reasons()) result->add_verdict_reasons(s.name() + ": " + r);
    }
    if (!holds.empty()) result->add_verdict_reasons("held on " + join(holds));
  } else if (!holds.empty()) {
    verdict = proto::VerifyResult::HOLDS;
    result->add_verdict_reasons("held on " + join(holds));
  } else if (result->sequences_size() == 0) {
    result->add_verdict_reasons("no sequence");
  } else {
    for (const proto::SequenceVerification& s : result->sequences()) {
      for (const std::string& r : s.reasons()) result->add_verdict_reasons(s.name() + ": " + r);
    }
  }
  if (!cannot_tell.empty() && verdict != proto::VerifyResult::CANNOT_TELL) {
    result->add_verdict_reasons("cannot tell on " + join(cannot_tell));
  }
  result->set_verdict(verdict);
}

}  // namespace tiltcal::verify
