// tiltcal_gravity: inclination and flat-ground gravity reference of a sequence.
#include <iostream>

#include "common/cli/command_line.h"
#include "common/io/params.h"
#include "stages/gravity/default_params_text.h"
#include "stages/gravity/gravity.h"
#include "tiltcal/proto/gravity_params.pb.h"

namespace {

int Main(int argc, char** argv) {
  using tiltcal::cli::kRequired;
  tiltcal::cli::CommandLine cli("tiltcal_gravity",
                                "inclination and flat-ground gravity reference of a sequence");
  cli.AddFlag("imu", "input: imu.binpb", kRequired);
  cli.AddFlag("ground", "input, optional: ground.binpb (gives the ground slope per scan)");
  cli.AddFlag("rig", "input: the dataset's rig.txtpb", kRequired);
  cli.AddFlag("calibration", "input, optional: calibration.txtpb of a flat-ground run");
  cli.AddFlag("params",
              "input: gravity params, text format (default: "
              "stages/gravity/default_params.txtpb, compiled in)");
  cli.AddFlag("out", "output: gravity.txtpb", kRequired);
  cli.AddExample(
      "tiltcal_gravity --imu=out/run1/imu.binpb --ground=out/run1/ground.binpb "
      "--rig=datasets/husky/rig.txtpb --out=out/run1/gravity.txtpb");
  if (const auto exit_code = cli.Parse(argc, argv)) return *exit_code;
  tiltcal::gravity::GravityPaths paths;
  paths.imu = cli.Get("imu");
  paths.ground = cli.Get("ground");
  paths.rig = cli.Get("rig");
  paths.calibration = cli.Get("calibration");
  paths.params = cli.Get("params");
  paths.out = cli.Get("out");
  paths.command_line = cli.command_line();
  tiltcal::proto::GravityParams params;
  tiltcal::Status status = tiltcal::LoadParamsOrDefaults(
      paths.params, tiltcal::gravity::DefaultParamsText(), &params);
  if (status.ok()) status = tiltcal::gravity::Run(paths, params, &std::cerr);
  return cli.Finish(status);
}

}  // namespace

int main(int argc, char** argv) {
  return tiltcal::cli::RunMain("tiltcal_gravity", Main, argc, argv);
}
