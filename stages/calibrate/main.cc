// tiltcal_calibrate: continuous-time LiDAR-IMU calibration.
#include <iostream>

#include <glog/logging.h>

#include "common/cli/command_line.h"
#include "stages/calibrate/calibrate.h"
#include "stages/calibrate/calibrate_params_validation.h"
#include "stages/calibrate/report/verdict.h"

namespace {

int Main(int argc, char** argv) {
  using tiltcal::cli::kRequired;
  tiltcal::cli::CommandLine cli("tiltcal_calibrate",
                                "continuous-time LiDAR-IMU calibration: extrinsic, time offset, "
                                "gravity and IMU biases with their uncertainties");
  cli.AddFlag("imu", "input: imu.binpb", kRequired);
  cli.AddFlag("scans", "input: scans.binpb.lz4 (raw scans, not deskewed)", kRequired);
  cli.AddFlag("ground", "input: ground.binpb (for the ground residuals)");
  cli.AddFlag("gravity", "input: gravity.txtpb (the flat-ground gravity reference)");
  cli.AddFlag("rig", "input: the dataset's rig.txtpb", kRequired);
  cli.AddFlag("params", "input: params (default: stages/calibrate/default_params.txtpb)");
  cli.AddFlag("out", "output: calibration.txtpb", kRequired);
  cli.AddFlag("out_map_rig", "output, optional: map_rig.pcd (the scans with the rig's extrinsic)");
  cli.AddFlag("out_map_calibrated",
              "output, optional: map_calibrated.pcd (the scans with the estimate)");
  cli.AddSwitch("quiet", "no progress lines on stderr");
  cli.AddExample(
      "tiltcal_calibrate --imu=out/run1/imu.binpb --scans=out/run1/scans.binpb.lz4 "
      "--ground=out/run1/ground.binpb --gravity=out/run1/gravity.txtpb "
      "--rig=datasets/husky/rig.txtpb --out=out/run1/calibration.txtpb");
  cli.AddExitCode(tiltcal::cli::kExitSuspect,
                  "result written but its verdict is SUSPECT (reasons in the file and on "
                  "stderr; params verdict.allow_suspect: true exits 0)");
  if (const auto exit_code = cli.Parse(argc, argv)) return *exit_code;
  // Ceres also logs a failed solve through glog; its message is already in
  // the stage's one error line (solve_check.h), so glog prints nothing.
  FLAGS_minloglevel = google::GLOG_FATAL;
  tiltcal::calibrate::CalibratePaths paths;
  paths.imu = cli.Get("imu");
  paths.scans = cli.Get("scans");
  paths.ground = cli.Get("ground");
  paths.gravity = cli.Get("gravity");
  paths.rig = cli.Get("rig");
  paths.params = cli.Get("params");
  paths.out = cli.Get("out");
  paths.out_map_rig = cli.Get("out_map_rig");
  paths.out_map_calibrated = cli.Get("out_map_calibrated");
  paths.command_line = cli.command_line();
  tiltcal::proto::CalibrateParams params;
  tiltcal::Status status = tiltcal::calibrate::LoadCalibrateParams(paths.params, &params);
  tiltcal::proto::CalibrationResult result;
  if (status.ok()) {
    status = tiltcal::calibrate::Run(paths, params, cli.GetSwitch("quiet") ? nullptr : &std::cerr,
                                     &result);
  }
  if (!status.ok()) return cli.Finish(status);
  std::cerr << "tiltcal_calibrate: " << tiltcal::calibrate::FormatVerdict(result, params.verdict())
            << "\n";
  if (result.verdict() == tiltcal::proto::CalibrationResult::SUSPECT &&
      !params.verdict().allow_suspect()) {
    std::cerr << "tiltcal_calibrate: " << paths.out << " is SUSPECT: read the reasons above\n";
    return tiltcal::cli::kExitSuspect;
  }
  return tiltcal::cli::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  return tiltcal::cli::RunMain("tiltcal_calibrate", Main, argc, argv);
}
