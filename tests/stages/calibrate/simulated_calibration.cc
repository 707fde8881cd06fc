#include "tests/stages/calibrate/simulated_calibration.h"

#include <Eigen/Geometry>

#include "common/geometry/angles.h"
#include "common/io/eigen_proto.h"

namespace tiltcal::calibrate {

void SimulateAndDecode(const proto::SimulateParams& scenario, const testing::TempDir& dir,
                       const std::string& name, SimulatedInputs* inputs) {
  const std::string scenario_path = dir.File(name + "_scenario.txtpb");
  ASSERT_TRUE(WriteTextProto(scenario_path, scenario).ok());
  inputs->bag = dir.File(name + ".bag");
  inputs->rig = dir.File(name + "_rig.txtpb");
  inputs->imu = dir.File(name + "_imu.binpb");
  inputs->scans = dir.File(name + "_scans.binpb.lz4");
  const std::string truth_path = dir.File(name + "_truth.txtpb");
  std::string output;
  ASSERT_EQ(testing::RunCommand(testing::ToolPath("tiltcal_simulate") + " --quiet --params=" +
                                    scenario_path + " --out_bag=" + inputs->bag +
                                    " --out_truth=" + truth_path + " --out_rig=" + inputs->rig,
                                &output),
            0)
      << output;
  ASSERT_EQ(testing::RunCommand(testing::ToolPath("tiltcal_decode") + " --bag=" + inputs->bag +
                                    " --rig=" + inputs->rig + " --out_imu=" + inputs->imu +
                                    " --out_scans=" + inputs->scans,
                                &output),
            0)
      << output;
  ASSERT_TRUE(ReadTextProto(truth_path, &inputs->truth).ok());
}

CalibrationRun RunCalibrate(const SimulatedInputs& inputs, const proto::CalibrateParams& params,
                            const testing::TempDir& dir, const std::string& name) {
  CalibrationRun run;
  const std::string params_path = dir.File(name + "_params.txtpb");
  if (!WriteTextProto(params_path, params).ok()) return run;
  const std::string out = dir.File(name + "_calibration.txtpb");
  run.exit_code = testing::RunCommand(testing::ToolPath("tiltcal_calibrate") + " --imu=" +
                                          inputs.imu + " --scans=" + inputs.scans + " --rig=" +
                                          inputs.rig + " --params=" + params_path + " --out=" + out,
                                      &run.output);
  run.has_result = ReadTextProto(out, &run.result).ok();
  if (!run.has_result) return run;
  const Rigid3d estimate = ToEigen(run.result.imu_from_lidar());
  const Rigid3d truth = ToEigen(inputs.truth.imu_from_lidar());
  run.rotation_deg =
      geometry::RadToDeg(Eigen::AngleAxisd(estimate.rotation * truth.rotation.conjugate()).angle());
  run.translation_m = estimate.translation - truth.translation;
  run.tau_ms = (run.result.time_offset_s() - inputs.truth.time_offset_s()) * 1e3;
  run.max_rotation_sigma_deg = ToEigen(run.result.rotation_sigma_deg()).maxCoeff();
  return run;
}

}  // namespace tiltcal::calibrate
