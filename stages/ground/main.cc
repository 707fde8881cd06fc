// tiltcal_ground: deskews LiDAR scans with the gyro, segments their ground and
// fits one ground plane per scan (n_l, d_l in the LiDAR frame at the stamp).
#include <iostream>

#include "common/cli/command_line.h"
#include "common/io/params.h"
#include "stages/ground/default_params_text.h"
#include "stages/ground/ground_stage.h"
#include "tiltcal/proto/ground_params.pb.h"

namespace {

int Main(int argc, char** argv) {
  using tiltcal::cli::kRequired;
  tiltcal::cli::CommandLine cli("tiltcal_ground",
                                "deskews scans and fits one ground plane per scan");
  cli.AddFlag("imu", "input: IMU stream (imu.binpb)", kRequired);
  cli.AddFlag("scans", "input: scan stream (scans.binpb.lz4)", kRequired);
  cli.AddFlag("rig", "input: the dataset's rig.txtpb", kRequired);
  cli.AddFlag("params",
              "input: ground params, text format (default: stages/ground/default_params.txtpb, "
              "compiled in)");
  cli.AddFlag("out_ground", "output: one ground plane per scan (ground.binpb)", kRequired);
  cli.AddFlag("out_scans", "output, optional: the deskewed scans (.binpb.lz4)");
  cli.AddExample(
      "tiltcal_ground --imu=out/run1/imu.binpb --scans=out/run1/scans.binpb.lz4 "
      "--rig=datasets/husky/rig.txtpb --out_ground=out/run1/ground.binpb");
  if (const auto exit_code = cli.Parse(argc, argv)) return *exit_code;
  tiltcal::ground::GroundPaths paths;
  paths.imu = cli.Get("imu");
  paths.scans = cli.Get("scans");
  paths.rig = cli.Get("rig");
  paths.params = cli.Get("params");
  paths.out_ground = cli.Get("out_ground");
  paths.out_scans = cli.Get("out_scans");
  paths.command_line = cli.command_line();
  tiltcal::proto::GroundParams params;
  tiltcal::Status status = tiltcal::LoadParamsOrDefaults(
      paths.params, tiltcal::ground::DefaultParamsText(), &params);
  if (status.ok()) status = tiltcal::ground::Run(paths, params, &std::cerr);
  return cli.Finish(status);
}

}  // namespace

int main(int argc, char** argv) {
  return tiltcal::cli::RunMain("tiltcal_ground", Main, argc, argv);
}
