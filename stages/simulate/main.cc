// tiltcal_simulate: a ground vehicle on a tilted plane with an IMU and a
// spinning LiDAR; writes a ROS1 bag, the ground truth and optionally a rig.
#include <iostream>

#include "common/cli/command_line.h"
#include "common/io/params.h"
#include "stages/simulate/simulate.h"
#include "tiltcal/proto/simulate_params.pb.h"

namespace {

int Main(int argc, char** argv) {
  tiltcal::cli::CommandLine cli(
      "tiltcal_simulate",
      "simulates a LiDAR-IMU rig on a tilted plane: a real ROS1 bag, the ground truth and "
      "optionally a rig.txtpb");
  cli.AddFlag("params", "input: the scenario (tiltcal.proto.SimulateParams, text format)",
              tiltcal::cli::kRequired);
  cli.AddFlag("out_bag", "output: the ROS1 bag", tiltcal::cli::kRequired);
  cli.AddFlag("out_truth", "output: the truth (tiltcal.proto.SimulationTruth, text format)",
              tiltcal::cli::kRequired);
  cli.AddFlag("out_rig", "output: a rig.txtpb (true extrinsic + the scenario's rig_file error)");
  cli.AddSwitch("quiet", "no progress and no summary on stderr");
  cli.AddExample(
      "tiltcal_simulate --params=stages/simulate/scenarios/tilted_husky_vlp16.txtpb "
      "--out_bag=datasets/sim/run1.bag --out_truth=datasets/sim/run1_truth.txtpb "
      "--out_rig=datasets/sim/rig.txtpb");
  if (const auto exit_code = cli.Parse(argc, argv)) return *exit_code;
  tiltcal::simulate::SimulatePaths paths;
  paths.params = cli.Get("params");
  paths.out_bag = cli.Get("out_bag");
  paths.out_truth = cli.Get("out_truth");
  paths.out_rig = cli.Get("out_rig");
  paths.command_line = cli.command_line();
  tiltcal::proto::SimulateParams params;
  tiltcal::Status status = tiltcal::LoadParams(paths.params, &params);
  if (status.ok()) {
    status = tiltcal::simulate::Run(paths, params, cli.GetSwitch("quiet") ? nullptr : &std::cerr);
  }
  return cli.Finish(status);
}

}  // namespace

int main(int argc, char** argv) {
  return tiltcal::cli::RunMain("tiltcal_simulate", Main, argc, argv);
}
