// tiltcal_gravity: inclination and flat-ground gravity reference of a sequence.
//   tiltcal_gravity --imu=imu.binpb --ground=ground.binpb --rig=rig.txtpb
//                   --params=P [--calibration=flat/calibration.txtpb] --out=gravity.txtpb
#include <iostream>

#include <gflags/gflags.h>

#include "common/io/params.h"
#include "common/io/provenance.h"
#include "stages/gravity/gravity.h"

DEFINE_string(imu, "", "input: imu.binpb");
DEFINE_string(ground, "", "input: ground.binpb (optional, gives the ground slope per scan)");
DEFINE_string(rig, "", "input: the dataset's rig.txtpb");
DEFINE_string(calibration, "", "input: calibration.txtpb of a flat-ground run (optional)");
DEFINE_string(params, "", "input: params (stages/gravity/default_params.txtpb)");
DEFINE_string(out, "", "output: gravity.txtpb");

int main(int argc, char** argv) {
  gflags::SetUsageMessage(
      "inclination and flat-ground gravity reference\n"
      "  tiltcal_gravity --imu=IMU --ground=GROUND --rig=RIG --params=P [--calibration=C] "
      "--out=gravity.txtpb");
  const std::string command_line = tiltcal::JoinCommandLine(argc, argv);
  gflags::ParseCommandLineFlags(&argc, &argv, /*remove_flags=*/true);
  if (FLAGS_imu.empty() || FLAGS_rig.empty() || FLAGS_params.empty() || FLAGS_out.empty()) {
    std::cerr << "tiltcal_gravity: --imu, --rig, --params and --out are required (see --help)\n";
    return 2;
  }
  tiltcal::proto::GravityParams params;
  tiltcal::Status status = tiltcal::LoadParams(FLAGS_params, &params);
  if (status.ok()) {
    status = tiltcal::gravity::Run({FLAGS_imu, FLAGS_ground, FLAGS_rig, FLAGS_calibration,
                                    FLAGS_params, FLAGS_out, command_line},
                                   params, &std::cerr);
  }
  if (!status.ok()) {
    std::cerr << "tiltcal_gravity: " << status.message() << "\n";
    return 1;
  }
  return 0;
}
