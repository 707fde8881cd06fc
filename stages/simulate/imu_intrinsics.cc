#include "stages/simulate/imu_intrinsics.h"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "common/geometry/angles.h"
#include "common/io/eigen_proto.h"
#include "stages/simulate/random.h"

namespace tiltcal::simulate {

namespace {

using geometry::kRadPerDeg;
constexpr double kMaxScalePpm = 1e5;
constexpr double kMaxMisalignmentDeg = 5.0;

// The given value plus bound · u, u uniform in [−1, 1). Every component
// draws its number whatever its bound, so the draws of one field do not
// depend on the others' bounds.
double GivenPlusDraw(double given, double bound, Rng* rng) {
  const double u = rng->Uniform(-1.0, 1.0);
  return given + bound * u;
}

TriadErrors Draw(const proto::SimTriadErrors& p, Rng* rng) {
  TriadErrors e;
  const Eigen::Vector3d scale_ppm = ToEigen(p.scale_ppm());
  const Eigen::Vector3d misalignment_deg = ToEigen(p.misalignment_deg());
  for (int a = 0; a < 3; ++a) {
    e.scale[a] = GivenPlusDraw(scale_ppm[a], p.scale_max_ppm(), rng) * 1e-6;
  }
  for (int a = 0; a < 3; ++a) {
    e.misalignment_rad[a] =
        GivenPlusDraw(misalignment_deg[a], p.misalignment_max_deg(), rng) * kRadPerDeg;
  }
  return e;
}

}  // namespace

Eigen::Matrix3d TriadErrors::MeasuredFromTrue() const {
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k.diagonal() += scale;
  k(1, 0) = misalignment_rad[0];
  k(2, 0) = misalignment_rad[1];
  k(2, 1) = misalignment_rad[2];
  return k;
}

Status SimTriadErrorsAreValid(const proto::SimTriadErrors& p, const char* field) {
  const Eigen::Vector3d scale_ppm = ToEigen(p.scale_ppm());
  const Eigen::Vector3d misalignment_deg = ToEigen(p.misalignment_deg());
  if (!scale_ppm.allFinite() ||
      scale_ppm.cwiseAbs().maxCoeff() + p.scale_max_ppm() > kMaxScalePpm) {
    return Status::Error(fmt::format(
        "field {}.scale_ppm: |scale_ppm| + scale_max_ppm must be at most {} ppm per axis", field,
        kMaxScalePpm));
  }
  if (!misalignment_deg.allFinite() ||
      misalignment_deg.cwiseAbs().maxCoeff() + p.misalignment_max_deg() > kMaxMisalignmentDeg) {
    return Status::Error(fmt::format(
        "field {}.misalignment_deg: |misalignment_deg| + misalignment_max_deg must be at most {} "
        "deg per angle",
        field, kMaxMisalignmentDeg));
  }
  return Status::Ok();
}

void DrawImuIntrinsics(const proto::SimFaultParams& faults, uint64_t seed, TriadErrors* gyro,
                       TriadErrors* accel) {
  Rng rng(seed, kImuIntrinsicsStream);
  *gyro = Draw(faults.gyro_intrinsics(), &rng);
  *accel = Draw(faults.accel_intrinsics(), &rng);
}

proto::TruthTriadErrors ToTruth(const TriadErrors& errors) {
  proto::TruthTriadErrors t;
  *t.mutable_scale_ppm() = ToProto(Eigen::Vector3d(errors.scale * 1e6));
  *t.mutable_misalignment_deg() = ToProto(Eigen::Vector3d(errors.misalignment_rad / kRadPerDeg));
  const Eigen::Matrix3d k = errors.MeasuredFromTrue();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) t.add_measured_from_true(k(r, c));
  }
  return t;
}

}  // namespace tiltcal::simulate
