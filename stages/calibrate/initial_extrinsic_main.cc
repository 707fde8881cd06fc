// tiltcal_initial_extrinsic: the sequence's rig with the starting extrinsic
// (rig, /tf_static or none, its rotation corrected from the motion).
#include <iostream>

#include <glog/logging.h>

#include "common/cli/command_line.h"
#include "stages/calibrate/calibrate_params_validation.h"
#include "stages/calibrate/init/initial_extrinsic.h"

namespace {

int Main(int argc, char** argv) {
  using tiltcal::cli::kRequired;
  tiltcal::cli::CommandLine cli(
      "tiltcal_initial_extrinsic",
      "the starting IMU-from-LiDAR extrinsic of one sequence: from the rig, else the bag's "
      "/tf_static, else none, its rotation corrected by any angle from the motion; writes the "
      "sequence's rig, which ground, gravity and calibrate read");
  cli.AddFlag("imu", "input: imu.binpb", kRequired);
  cli.AddFlag("scans", "input: scans.binpb.lz4 (raw scans)", kRequired);
  cli.AddFlag("rig", "input: the dataset's rig.txtpb (imu_from_lidar optional)", kRequired);
  cli.AddFlag("params",
              "input: calibrate params (default: stages/calibrate/default_params.txtpb; reads "
              "rotation_search, init, odometry, hand_eye, scans, spline, imu_noise, "
              "static_detection)");
  cli.AddFlag("out", "output: the sequence's rig.txtpb", kRequired);
  cli.AddSwitch("quiet", "no progress lines on stderr");
  cli.AddExample(
      "tiltcal_initial_extrinsic --imu=out/run1/imu.binpb --scans=out/run1/scans.binpb.lz4 "
      "--rig=datasets/husky/rig.txtpb --out=out/run1/rig.txtpb");
  if (const auto exit_code = cli.Parse(argc, argv)) return *exit_code;
  FLAGS_minloglevel = google::GLOG_FATAL;
  tiltcal::calibrate::InitialExtrinsicPaths paths;
  paths.imu = cli.Get("imu");
  paths.scans = cli.Get("scans");
  paths.rig = cli.Get("rig");
  paths.out = cli.Get("out");
  tiltcal::proto::CalibrateParams params;
  tiltcal::Status status = tiltcal::calibrate::LoadCalibrateParams(cli.Get("params"), &params);
  tiltcal::proto::Rig rig;
  if (status.ok()) {
    status = tiltcal::calibrate::RunInitialExtrinsic(
        paths, params, cli.GetSwitch("quiet") ? nullptr : &std::cerr, &rig);
  }
  return cli.Finish(status);
}

}  // namespace

int main(int argc, char** argv) {
  return tiltcal::cli::RunMain("tiltcal_initial_extrinsic", Main, argc, argv);
}
