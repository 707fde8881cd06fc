// tiltcal_simulate: a ground vehicle on a tilted plane with an IMU and a
// spinning LiDAR; writes a ROS1 bag, the ground truth and optionally a rig.
//   tiltcal_simulate --params=scenario.txtpb --out_bag=x.bag --out_truth=truth.txtpb
//                    [--out_rig=rig.txtpb]
#include <unistd.h>

#include <cstdio>
#include <iostream>

#include <gflags/gflags.h>

#include "common/io/params.h"
#include "common/io/provenance.h"
#include "stages/simulate/simulate.h"
#include "tiltcal/proto/simulate_params.pb.h"

DEFINE_string(params, "", "scenario (tiltcal.proto.SimulateParams, text format)");
DEFINE_string(out_bag, "", "output ROS1 bag");
DEFINE_string(out_truth, "", "output truth (tiltcal.proto.SimulationTruth, text format)");
DEFINE_string(out_rig, "", "optional output rig.txtpb (true extrinsic + params.rig_file error)");
DEFINE_bool(quiet, false, "no summary on stderr");

int main(int argc, char** argv) {
  const std::string command_line = tiltcal::JoinCommandLine(argc, argv);
  gflags::SetUsageMessage(
      "simulates a LiDAR-IMU rig on a tilted plane\n"
      "  tiltcal_simulate --params=scenario.txtpb --out_bag=x.bag --out_truth=truth.txtpb "
      "[--out_rig=rig.txtpb]");
  gflags::ParseCommandLineFlags(&argc, &argv, /*remove_flags=*/true);
  if (FLAGS_params.empty() || FLAGS_out_bag.empty() || FLAGS_out_truth.empty()) {
    std::cerr << "tiltcal_simulate: --params, --out_bag and --out_truth are required\n";
    return 2;
  }
  tiltcal::proto::SimulateParams params;
  tiltcal::Status status = tiltcal::LoadParams(FLAGS_params, &params);
  if (status.ok()) {
    tiltcal::simulate::SimulatePaths paths;
    paths.params = FLAGS_params;
    paths.out_bag = FLAGS_out_bag;
    paths.out_truth = FLAGS_out_truth;
    paths.out_rig = FLAGS_out_rig;
    paths.command_line = command_line;
    status = tiltcal::simulate::Run(paths, params, FLAGS_quiet ? nullptr : &std::cerr);
  }
  if (!status.ok()) {
    std::cerr << "tiltcal_simulate: " << status.message() << "\n";
    return 1;
  }
  return 0;
}
