// tiltcal_decode --bag=IN.bag --params=P.txtpb [--rig=rig.txtpb]
//                --out_imu=imu.binpb --out_scans=scans.binpb.lz4
// Decodes the IMU and LiDAR topics of a ROS1 bag into record streams.
#include <cstdio>
#include <iostream>

#include <gflags/gflags.h>

#include "common/io/params.h"
#include "common/io/provenance.h"
#include "stages/decode/decode.h"
#include "tiltcal/proto/decode_params.pb.h"

DEFINE_string(bag, "", "input ROS1 bag (.bag)");
DEFINE_string(params, "", "decode params (text format; see stages/decode/default_params.txtpb)");
DEFINE_string(rig, "", "optional rig.txtpb (imu_topic / lidar_topic)");
DEFINE_string(out_imu, "", "output IMU stream (imu.binpb)");
DEFINE_string(out_scans, "", "output scan stream (scans.binpb.lz4)");

int main(int argc, char** argv) {
  const std::string command_line = tiltcal::JoinCommandLine(argc, argv);
  gflags::SetUsageMessage(
      "--bag=IN.bag --params=P.txtpb [--rig=rig.txtpb] --out_imu=imu.binpb "
      "--out_scans=scans.binpb.lz4");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  tiltcal::Status status = tiltcal::Status::Ok();
  tiltcal::proto::DecodeParams params;
  if (FLAGS_params.empty()) {
    status = tiltcal::Status::Error(
        "--params is required (start from stages/decode/default_params.txtpb)");
  } else {
    status = tiltcal::LoadParams(FLAGS_params, &params);
  }
  if (status.ok()) {
    tiltcal::DecodePaths paths;
    paths.bag = FLAGS_bag;
    paths.rig = FLAGS_rig;
    paths.out_imu = FLAGS_out_imu;
    paths.out_scans = FLAGS_out_scans;
    paths.params = FLAGS_params;
    paths.command_line = command_line;
    status = tiltcal::Run(paths, params, &std::cerr);
  }
  if (!status.ok()) {
    std::fprintf(stderr, "tiltcal_decode: %s\n", status.message().c_str());
    return 1;
  }
  return 0;
}
