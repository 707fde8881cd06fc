#ifndef TILTCAL_STAGES_CALIBRATE_CALIBRATE_H_
#define TILTCAL_STAGES_CALIBRATE_CALIBRATE_H_

// tiltcal_calibrate: the continuous-time LiDAR-IMU calibration
// (docs/design.md §3, §6-§11).
//
// Pipeline (Calibrate):
//   initialisation (initialisation.h): IMU bias / gravity, gyro rotation
//     spline, LiDAR odometry on deskewed scans, extrinsic from the rig (or
//     hand-eye when excited), position spline;
//   outer iterations (OuterLoopParams): surfel map + association with the
//     current state (lidar_association.h), problem build
//     (problem_builder.h: gyro, accel, point-to-plane, ground when available),
//     LM solve (SPARSE_NORMAL_CHOLESKY);
//   covariance and observability report (covariance_report.h);
//   the facts of the verdict (residual statistics, map sharpness with the
//   estimate and with the rig, move from the rig) and the verdict
//   (verdict.h);
//   re-expression in the gauge C_ab(t0) = 1, r_a^{ba}(t0) = 0.
// Times: seconds from the first IMU stamp; LiDAR point times
// t_j = scan stamp + time_offset_ns (LiDAR clock), at IMU time t_j + tau.

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "common/imu/imu_reading.h"
#include "common/status.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "stages/calibrate/problem/lidar_scans.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/calibration.pb.h"
#include "tiltcal/proto/gravity.pb.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/rig.pb.h"

namespace tiltcal::calibrate {

struct CalibratePaths {
  std::string imu;      // imu.binpb
  std::string scans;    // scans.binpb.lz4 (raw, not deskewed)
  std::string ground;   // ground.binpb (optional)
  std::string gravity;  // gravity.txtpb (optional)
  std::string rig;      // rig.txtpb
  std::string params;   // for the provenance
  std::string out;      // calibration.txtpb
  // Optional before/after maps (map_export.h): the scans with the rig's
  // extrinsic and with the estimate, binary PCD.
  std::string out_map_rig;
  std::string out_map_calibrated;
  std::string command_line;
};

// Everything the calibration is computed from, already read.
struct CalibrateInputs {
  std::vector<imu::ImuReading> imu;  // times from first_imu_stamp_ns
  int64_t first_imu_stamp_ns = 0;
  std::string imu_source;  // where imu was read from (names it in errors)
  std::vector<LidarScan> scans;
  std::vector<proto::GroundPlane> ground;  // may be empty
  bool has_gravity = false;
  proto::GravityReference gravity;
  proto::Rig rig;
  // The IMU readings were thinned to every imu_decimation-th sample
  // (imu_vibration.h); 1 when not.
  int imu_decimation = 1;
  // How much their residuals understate their noise at low frequencies
  // (LowPassCorrelation, imu_vibration.h); 1 when not filtered.
  double imu_low_pass_correlation = 1.0;
  // tiltcal_decode's clock-drift note in imu.binpb's provenance ("" without).
  std::string clock_drift;
};

// Reads and checks the inputs (errors name the file and record).
Status ReadCalibrateInputs(const CalibratePaths& paths, const proto::CalibrateParams& params,
                           CalibrateInputs* inputs);

// The I/O-free pipeline. Fills *result (everything but the provenance) and,
// when final_state is not null, the final state. Progress lines go to log
// (may be null).
Status Calibrate(const CalibrateInputs& inputs, const proto::CalibrateParams& params,
                 proto::CalibrationResult* result, CalibrationState* final_state,
                 std::ostream* log);

// Calibrate on the readings as tiltcal_calibrate weighs them: a vibrating
// IMU is first low-passed and thinned (report/imu_vibration.h: *inputs'
// readings are replaced and the solve weighs them with the thinned sigmas,
// params' imu_noise divided by sqrt of the thinning); its report and note go
// into *result.
Status CalibrateSequence(const proto::CalibrateParams& params, CalibrateInputs* inputs,
                         proto::CalibrationResult* result, CalibrationState* final_state,
                         std::ostream* log);

// Reads, calibrates, writes the maps when asked and then calibration.txtpb,
// each atomically, the calibration with provenance;
// the result written (with its verdict) also goes to *written when not null.
// A SUSPECT verdict is not an error here: the caller decides (main exits
// cli::kExitSuspect unless VerdictParams.allow_suspect).
Status Run(const CalibratePaths& paths, const proto::CalibrateParams& params, std::ostream* log,
           proto::CalibrationResult* written = nullptr);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_CALIBRATE_H_
