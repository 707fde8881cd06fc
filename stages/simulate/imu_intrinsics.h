#ifndef TILTCAL_STAGES_SIMULATE_IMU_INTRINSICS_H_
#define TILTCAL_STAGES_SIMULATE_IMU_INTRINSICS_H_

#include <cstdint>

#include <Eigen/Core>

#include "common/status.h"
#include "tiltcal/proto/simulate_params.pb.h"
#include "tiltcal/proto/truth.pb.h"

namespace tiltcal::simulate {

// Scale factor and axis misalignment of one sensor triad (gyroscope or
// accelerometer), the intrinsic errors of a consumer-grade IMU:
//   measured = K · true,   K = I + S + M   (exactly this linear map),
// `true` resolved in the IMU frame b. S = diag(s_x, s_y, s_z), the scale
// errors (fractions; the params give ppm). M is strictly lower triangular,
//   M = [ 0     0     0 ]
//       [ m_yx  0     0 ]
//       [ m_zx  m_zy  0 ],
// small angles in rad: the triad's x axis is b's x axis, its y axis lies in
// b's x-y plane, tilted by m_yx towards +x, and its z axis is tilted by m_zx
// towards +x and by m_zy towards +y. So frame b is defined by the triad
// itself (x axis and x-y plane), each triad separately.
struct TriadErrors {
  Eigen::Vector3d scale = Eigen::Vector3d::Zero();             // s_x, s_y, s_z (fractions)
  Eigen::Vector3d misalignment_rad = Eigen::Vector3d::Zero();  // m_yx, m_zx, m_zy
  // K = I + S + M.
  Eigen::Matrix3d MeasuredFromTrue() const;
  bool IsIdentity() const { return scale.isZero(0.0) && misalignment_rad.isZero(0.0); }
};

// Checks the bounds the schema cannot state (Vector3 components): every
// scale at most 1e5 ppm and every misalignment at most 5 deg in magnitude,
// given plus drawn. `field` names the message in the error
// ("faults.gyro_intrinsics").
Status SimTriadErrorsAreValid(const proto::SimTriadErrors& params, const char* field);

// The errors of the params: the given values plus, when a bound is set,
// a uniform draw in [−bound, bound] per component (scales first, x y z, then
// the angles m_yx m_zx m_zy), from the IMU intrinsics stream of `seed`
// (random.h); the gyroscope draws first, then the accelerometer, so a
// setting of one leaves the other's values unchanged.
void DrawImuIntrinsics(const proto::SimFaultParams& faults, uint64_t seed, TriadErrors* gyro,
                       TriadErrors* accel);

// The truth record of a triad's errors (ppm, deg and K).
proto::TruthTriadErrors ToTruth(const TriadErrors& errors);

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_IMU_INTRINSICS_H_
