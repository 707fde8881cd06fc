// tiltcal_calibrate: continuous-time LiDAR-IMU calibration.
//   tiltcal_calibrate --imu=imu.binpb --scans=scans.binpb.lz4 [--ground=ground.binpb]
//                     [--gravity=gravity.txtpb] --rig=rig.txtpb --params=P
//                     --out=calibration.txtpb
#include <iostream>

#include <gflags/gflags.h>

#include "common/io/params.h"
#include "common/io/provenance.h"
#include "stages/calibrate/calibrate.h"

DEFINE_string(imu, "", "input: imu.binpb");
DEFINE_string(scans, "", "input: scans.binpb.lz4 (raw scans, not deskewed)");
DEFINE_string(ground, "", "input: ground.binpb (optional)");
DEFINE_string(gravity, "", "input: gravity.txtpb (optional)");
DEFINE_string(rig, "", "input: the dataset's rig.txtpb");
DEFINE_string(params, "", "input: params (stages/calibrate/default_params.txtpb)");
DEFINE_string(out, "", "output: calibration.txtpb");
DEFINE_bool(quiet, false, "no progress lines on stderr");

int main(int argc, char** argv) {
  gflags::SetUsageMessage(
      "continuous-time LiDAR-IMU calibration\n"
      "  tiltcal_calibrate --imu=IMU --scans=SCANS [--ground=G] [--gravity=GRAV] --rig=RIG "
      "--params=P --out=calibration.txtpb");
  const std::string command_line = tiltcal::JoinCommandLine(argc, argv);
  gflags::ParseCommandLineFlags(&argc, &argv, /*remove_flags=*/true);
  if (FLAGS_imu.empty() || FLAGS_scans.empty() || FLAGS_rig.empty() || FLAGS_params.empty() ||
      FLAGS_out.empty()) {
    std::cerr << "tiltcal_calibrate: --imu, --scans, --rig, --params and --out are required "
                 "(see --help)\n";
    return 2;
  }
  tiltcal::proto::CalibrateParams params;
  tiltcal::Status status = tiltcal::LoadParams(FLAGS_params, &params);
  if (status.ok()) {
    status = tiltcal::calibrate::Run({FLAGS_imu, FLAGS_scans, FLAGS_ground, FLAGS_gravity,
                                      FLAGS_rig, FLAGS_params, FLAGS_out, command_line},
                                     params, FLAGS_quiet ? nullptr : &std::cerr);
  }
  if (!status.ok()) {
    std::cerr << "tiltcal_calibrate: " << status.message() << "\n";
    return 1;
  }
  return 0;
}
