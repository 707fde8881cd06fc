// tiltcal_dataset_calibration: one extrinsic from the calibrations of a
// dataset's sequences, with each sequence's consistency.
#include <iostream>

#include "common/cli/command_line.h"
#include "common/io/params.h"
#include "stages/dataset_calibration/dataset_calibration.h"
#include "stages/dataset_calibration/default_params_text.h"
#include "tiltcal/proto/dataset_params.pb.h"

namespace {

int Main(int argc, char** argv) {
  tiltcal::cli::CommandLine cli(
      "tiltcal_dataset_calibration",
      "one extrinsic from the calibrations of a dataset's sequences (their information fused, "
      "each sequence tested for consistency with the joint value)");
  cli.SetPositional("CALIBRATION...", "out/<sequence>/calibration.txtpb of each sequence", 1, -1);
  cli.AddFlag("params",
              "input: params, text format (default: "
              "stages/dataset_calibration/default_params.txtpb, compiled in)");
  cli.AddFlag("out", "output: the dataset's calibration.txtpb", tiltcal::cli::kRequired);
  cli.AddExample(
      "tiltcal_dataset_calibration --out=datasets/husky/out/calibration.txtpb "
      "datasets/husky/out/*/calibration.txtpb");
  cli.AddExitCode(tiltcal::cli::kExitSuspect,
                  "result written but its verdict is SUSPECT (the used sequences disagree, or "
                  "fewer than consistency.min_sequences used)");
  if (const auto exit_code = cli.Parse(argc, argv)) return *exit_code;
  tiltcal::dataset::DatasetCalibrationPaths paths;
  paths.calibrations = cli.positional();
  paths.params = cli.Get("params");
  paths.out = cli.Get("out");
  paths.command_line = cli.command_line();
  tiltcal::proto::DatasetCalibrationParams params;
  tiltcal::Status status = tiltcal::LoadParamsOrDefaults(
      paths.params, tiltcal::dataset_calibration::DefaultParamsText(), &params);
  tiltcal::proto::CalibrationResult result;
  if (status.ok()) status = tiltcal::dataset::Run(paths, params, &std::cerr, &result);
  if (!status.ok()) return cli.Finish(status);
  if (result.verdict() == tiltcal::proto::CalibrationResult::SUSPECT) {
    std::cerr << "tiltcal_dataset_calibration: " << paths.out << " is SUSPECT: read the reasons above\n";
    return tiltcal::cli::kExitSuspect;
  }
  return tiltcal::cli::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  return tiltcal::cli::RunMain("tiltcal_dataset_calibration", Main, argc, argv);
}
