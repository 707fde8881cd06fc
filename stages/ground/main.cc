// tiltcal_ground: deskews LiDAR scans with the gyro, segments their ground and
// fits one ground plane per scan (n_l, d_l in the LiDAR frame at the stamp).
//   tiltcal_ground --imu=imu.binpb --scans=scans.binpb.lz4 --rig=rig.txtpb
//                  --params=ground.txtpb --out_ground=ground.binpb
//                  [--out_scans=deskewed.binpb.lz4]
#include <iostream>

#include <gflags/gflags.h>

#include "common/io/params.h"
#include "common/io/provenance.h"
#include "stages/ground/ground_stage.h"
#include "tiltcal/proto/ground_params.pb.h"

DEFINE_string(imu, "", "input IMU stream (imu.binpb)");
DEFINE_string(scans, "", "input scan stream (scans.binpb.lz4)");
DEFINE_string(rig, "", "rig description (rig.txtpb)");
DEFINE_string(params, "", "ground params (text format, see stages/ground/default_params.txtpb)");
DEFINE_string(out_ground, "", "output ground planes (ground.binpb)");
DEFINE_string(out_scans, "", "optional output of the deskewed scans (.binpb.lz4)");

int main(int argc, char** argv) {
  const std::string command_line = tiltcal::JoinCommandLine(argc, argv);
  gflags::SetUsageMessage(
      "deskews scans and fits one ground plane per scan\n"
      "  tiltcal_ground --imu=F --scans=F --rig=F --params=F --out_ground=F [--out_scans=F]");
  gflags::ParseCommandLineFlags(&argc, &argv, /*remove_flags=*/true);
  tiltcal::proto::GroundParams params;
  tiltcal::Status status = FLAGS_params.empty()
                               ? tiltcal::Status::Error("--params is required")
                               : tiltcal::LoadParams(FLAGS_params, &params);
  if (status.ok()) {
    tiltcal::ground::GroundPaths paths;
    paths.imu = FLAGS_imu;
    paths.scans = FLAGS_scans;
    paths.rig = FLAGS_rig;
    paths.params = FLAGS_params;
    paths.out_ground = FLAGS_out_ground;
    paths.out_scans = FLAGS_out_scans;
    paths.command_line = command_line;
    status = tiltcal::ground::Run(paths, params, &std::cerr);
  }
  if (!status.ok()) {
    std::cerr << "tiltcal_ground: " << status.message() << "\n";
    return 1;
  }
  return 0;
}
