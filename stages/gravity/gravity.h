#ifndef TILTCAL_STAGES_GRAVITY_GRAVITY_H_
#define TILTCAL_STAGES_GRAVITY_GRAVITY_H_

#include <ostream>
#include <string>
#include <vector>

#include "common/imu/imu_reading.h"
#include "common/status.h"
#include "tiltcal/proto/calibration.pb.h"
#include "tiltcal/proto/gravity.pb.h"
#include "tiltcal/proto/gravity_params.pb.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/rig.pb.h"

namespace tiltcal::gravity {

// Everything the estimate is computed from, already read.
struct GravityInputs {
  std::vector<imu::ImuReading> imu;  // times relative to first_imu_stamp_ns
  int64_t first_imu_stamp_ns = 0;
  std::vector<proto::GroundPlane> ground;   // may be empty
  proto::Rig rig;                           // passed ValidateRig (common/io/rig.h)
  // g_f given by the dataset: the rig's gravity_flat_in_imu or the file its
  // gravity_reference names (has_gravity_flat false otherwise).
  proto::GravityReference dataset_reference;
  std::string dataset_reference_source;     // "rig" or the reference path
  const proto::CalibrationResult* flat_calibration = nullptr;  // optional
};

// The gravity reference of one sequence (I/O free):
// - g_a and the gyro bias from the static start (or the first seconds), the
//   attitude C_ab(t) by gyro integration;
// - static windows of the accelerometer;
// - per scan: g̃_b = −C_ab(t)^T g_a / |g_a| at t = t_scan + τ, the ground slope
//   ∠(g̃_b, C_bl n_l) from the scan's ground plane and, when g_f is known, the
//   inclination φ with cos φ = g̃_b · g̃_f, g̃_f = −g_f / |g_f|
//   (docs/design.md §10);
// - the verdict level / tilted from a percentile of the ground slope
//   (params.level_verdict);
// - g_f: from the dataset when it names one; else on a level sequence from the
//   static windows (−|g| times the direction of the mean specific force) and
//   from a flat-ground calibration (its g_a), with their disagreement.
Status EstimateGravityReference(const GravityInputs& inputs, const proto::GravityParams& params,
                                proto::GravityReference* out);

// Paths of one tiltcal_gravity run (the flags of the same names).
struct GravityPaths {
  std::string imu;          // imu.binpb
  std::string ground;       // optional: ground.binpb
  std::string rig;          // rig.txtpb
  std::string calibration;  // optional: a flat-ground calibration.txtpb
  std::string params;       // the params file (provenance only; empty: the defaults)
  std::string out;          // gravity.txtpb
  std::string command_line;
};

// Reads the inputs, estimates, writes gravity.txtpb atomically with its
// provenance, and writes a summary to `log` (nullptr: silent).
Status Run(const GravityPaths& paths, const proto::GravityParams& params, std::ostream* log);

}  // namespace tiltcal::gravity

#endif  // TILTCAL_STAGES_GRAVITY_GRAVITY_H_
