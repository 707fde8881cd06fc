// tiltcal_decode: the IMU and LiDAR topics of a bag (ROS 1, MCAP, rosbag2, or
// one sequence in several bag files) into record streams.
#include <iostream>

#include "common/cli/command_line.h"
#include "common/io/params.h"
#include "stages/decode/decode.h"
#include "stages/decode/default_params_text.h"
#include "tiltcal/proto/decode_params.pb.h"

namespace {

int Main(int argc, char** argv) {
  tiltcal::cli::CommandLine cli(
      "tiltcal_decode",
      "decodes the IMU and LiDAR topics of a bag (ROS 1 with none / bz2 / lz4 chunks, indexed "
      "or not; MCAP; rosbag2 sqlite3) or of one sequence in several bag files into imu.binpb "
      "and scans.binpb.lz4");
  cli.AddFlag("bag",
              "input: a bag file (.bag, .mcap, .db3), a ROS 2 bag folder (metadata.yaml), or a "
              "folder of bag files holding one sequence (merged in record time)",
              tiltcal::cli::kRequired);
  cli.AddFlag("rig", "input: the dataset's rig.txtpb (imu_topic / lidar_topic)");
  cli.AddFlag("params",
              "decode params, text format (default: stages/decode/default_params.txtpb)");
  cli.AddFlag("out_imu", "output: the IMU stream (imu.binpb)", tiltcal::cli::kRequired);
  cli.AddFlag("out_scans", "output: the scan stream (scans.binpb.lz4)", tiltcal::cli::kRequired);
  cli.AddExample(
      "tiltcal_decode --bag=datasets/husky/run1.bag --rig=datasets/husky/rig.txtpb "
      "--out_imu=out/run1/imu.binpb --out_scans=out/run1/scans.binpb.lz4");
  if (const auto exit_code = cli.Parse(argc, argv)) return *exit_code;
  tiltcal::DecodePaths paths;
  paths.bag = cli.Get("bag");
  paths.rig = cli.Get("rig");
  paths.out_imu = cli.Get("out_imu");
  paths.out_scans = cli.Get("out_scans");
  paths.params = cli.Get("params");
  paths.command_line = cli.command_line();
  tiltcal::proto::DecodeParams params;
  tiltcal::Status status = tiltcal::LoadParamsOrDefaults(
      paths.params, tiltcal::decode::DefaultParamsText(), &params);
  if (status.ok()) status = tiltcal::Run(paths, params, &std::cerr);
  return cli.Finish(status);
}

}  // namespace

int main(int argc, char** argv) {
  return tiltcal::cli::RunMain("tiltcal_decode", Main, argc, argv);
}
