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
  tiltcal::simulate::SimulateSummary summary;
  if (status.ok()) {
    tiltcal::simulate::SimulateOutputs outputs;
    outputs.bag_path = FLAGS_out_bag;
    outputs.truth_path = FLAGS_out_truth;
    outputs.rig_path = FLAGS_out_rig;
    outputs.command_line = command_line;
    if (isatty(STDERR_FILENO) && !FLAGS_quiet) {
      outputs.progress = [](int done, int total) {
        std::fprintf(stderr, "\rtiltcal_simulate: scan %d / %d", done, total);
        if (done == total) std::fprintf(stderr, "\n");
      };
    }
    status = tiltcal::simulate::Run(params, outputs, &summary);
  }
  if (!status.ok()) {
    std::cerr << "tiltcal_simulate: " << status.message() << "\n";
    return 1;
  }
  if (!FLAGS_quiet) {
    std::fprintf(stderr,
                 "tiltcal_simulate: %d IMU samples, %d scans, %llu points, %.1f MB bag; "
                 "ray casting %.2f s, total %.2f s\n",
                 summary.num_imu_samples, summary.num_scans,
                 static_cast<unsigned long long>(summary.num_points), summary.bag_bytes / 1e6,
                 summary.raycast_seconds, summary.total_seconds);
  }
  return 0;
}
