// tiltcal_gravity_reference: a flat dataset's gravity reference g_f from the
// calibrations of its sequences.
#include <iostream>

#include "common/cli/command_line.h"
#include "common/io/params.h"
#include "stages/gravity/default_params_text.h"
#include "stages/gravity/gravity_reference.h"
#include "tiltcal/proto/gravity_params.pb.h"

namespace {

int Main(int argc, char** argv) {
  tiltcal::cli::CommandLine cli(
      "tiltcal_gravity_reference",
      "a flat dataset's gravity reference g_f from its sequences' calibrations (g_a with the "
      "accelerometer bias estimated), for the rig of a tilted dataset");
  cli.SetPositional("CALIBRATION...", "calibration.txtpb of each flat sequence", 1, -1);
  cli.AddFlag("params",
              "input: gravity params, text format (default: "
              "stages/gravity/default_params.txtpb, compiled in)");
  cli.AddFlag("out", "output: gravity_reference.txtpb", tiltcal::cli::kRequired);
  cli.AddExample(
      "tiltcal_gravity_reference --out=datasets/husky_flat/out/gravity_reference.txtpb "
      "datasets/husky_flat/out/*/calibration.txtpb");
  if (const auto exit_code = cli.Parse(argc, argv)) return *exit_code;
  tiltcal::gravity::GravityReferencePaths paths;
  paths.calibrations = cli.positional();
  paths.params = cli.Get("params");
  paths.out = cli.Get("out");
  paths.command_line = cli.command_line();
  tiltcal::proto::GravityParams params;
  tiltcal::Status status = tiltcal::LoadParamsOrDefaults(
      paths.params, tiltcal::gravity::DefaultParamsText(), &params);
  if (status.ok()) status = tiltcal::gravity::RunGravityReference(paths, params, &std::cerr);
  return cli.Finish(status);
}

}  // namespace

int main(int argc, char** argv) {
  return tiltcal::cli::RunMain("tiltcal_gravity_reference", Main, argc, argv);
}
