#ifndef TILTCAL_TESTS_STAGES_CALIBRATE_SIMULATED_CALIBRATION_H_
#define TILTCAL_TESTS_STAGES_CALIBRATE_SIMULATED_CALIBRATION_H_

// A scenario through the executables, as a user runs them: tiltcal_simulate,
// tiltcal_decode, then tiltcal_calibrate with given params, and the result
// against the truth.

#include <string>

#include <gtest/gtest.h>

#include <Eigen/Core>

#include "common/io/text_proto.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/calibration.pb.h"
#include "tiltcal/proto/simulate_params.pb.h"
#include "tiltcal/proto/truth.pb.h"

namespace tiltcal::calibrate {

// The decoded inputs of a simulated scenario, files in a test's folder.
struct SimulatedInputs {
  std::string bag, rig, imu, scans;
  proto::SimulationTruth truth;
};

// Simulates `scenario` and decodes it into dir/<name>_*; gtest failures
// (ASSERT) when a tool fails.
void SimulateAndDecode(const proto::SimulateParams& scenario, const testing::TempDir& dir,
                       const std::string& name, SimulatedInputs* inputs);

// One tiltcal_calibrate run and its errors against the truth.
struct CalibrationRun {
  int exit_code = -1;
  std::string output;  // stdout and stderr
  proto::CalibrationResult result;
  bool has_result = false;
  double rotation_deg = 0.0;  // angle of C_bl,est C_bl,true^T
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();  // estimate - truth, IMU frame
  double tau_ms = 0.0;
  double max_rotation_sigma_deg = 0.0;
};

// Calibrates the inputs with `params` into dir/<name>_calibration.txtpb.
CalibrationRun RunCalibrate(const SimulatedInputs& inputs, const proto::CalibrateParams& params,
                            const testing::TempDir& dir, const std::string& name);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_TESTS_STAGES_CALIBRATE_SIMULATED_CALIBRATION_H_
