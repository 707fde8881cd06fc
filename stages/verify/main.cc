// tiltcal_verify: does a stored calibration still hold for new recordings?
#include <iostream>

#include <glog/logging.h>

#include "common/cli/command_line.h"
#include "common/io/params.h"
#include "stages/calibrate/calibrate_params_validation.h"
#include "stages/verify/default_params_text.h"
#include "stages/verify/verify.h"

namespace {

int Main(int argc, char** argv) {
  using tiltcal::cli::kRequired;
  tiltcal::cli::CommandLine cli(
      "tiltcal_verify",
      "checks a stored calibration (the reference) against new recordings: each sequence "
      "calibrated again and its estimate compared with the reference (chi2 with both "
      "covariances, tau, map sharpness); verdict HOLDS, MOVED or CANNOT_TELL");
  cli.SetPositional("SEQUENCE_DIR...",
                    "out/<sequence> folders with imu.binpb, scans.binpb.lz4 (+ ground.binpb, "
                    "gravity.txtpb)",
                    1, -1);
  cli.AddFlag("reference", "input: the stored calibration.txtpb to check", kRequired);
  cli.AddFlag("params",
              "input: params, text format (default: stages/verify/default_params.txtpb, "
              "compiled in)");
  cli.AddFlag("calibrate_params",
              "input: the calibrate params the sequences are calibrated with (default: "
              "stages/calibrate/default_params.txtpb, compiled in)");
  cli.AddFlag("rig", "input: the dataset's rig.txtpb", kRequired);
  cli.AddFlag("out", "output: verify.txtpb", kRequired);
  cli.AddExample(
      "tiltcal_verify --reference=vehicle7/calibration.txtpb "
      "--out=datasets/d/out/verify.txtpb datasets/d/out/run1 datasets/d/out/run2");
  cli.AddExitCode(tiltcal::cli::kExitSuspect,
                  "verdict MOVED: a sequence's estimate differs from the reference (written; "
                  "what moved is in the reasons)");
  cli.AddExitCode(tiltcal::cli::kExitCannotTell,
                  "verdict CANNOT_TELL: no sequence can decide (written; the reasons name the "
                  "directions the recordings leave open)");
  if (const auto exit_code = cli.Parse(argc, argv)) return *exit_code;
  // Ceres also logs a failed solve through glog; the stage reports it itself.
  FLAGS_minloglevel = google::GLOG_FATAL;
  tiltcal::verify::VerifyPaths paths;
  paths.sequence_dirs = cli.positional();
  paths.reference = cli.Get("reference");
  paths.rig = cli.Get("rig");
  paths.params = cli.Get("params");
  paths.calibrate_params = cli.Get("calibrate_params");
  paths.out = cli.Get("out");
  paths.command_line = cli.command_line();
  tiltcal::proto::VerifyParams params;
  tiltcal::Status status =
      tiltcal::LoadParamsOrDefaults(paths.params, tiltcal::verify::DefaultParamsText(), &params);
  tiltcal::proto::CalibrateParams calibrate_params;
  if (status.ok()) {
    status = tiltcal::calibrate::LoadCalibrateParams(paths.calibrate_params, &calibrate_params);
  }
  tiltcal::proto::VerifyResult result;
  if (status.ok()) {
    status = tiltcal::verify::Run(paths, params, calibrate_params, &std::cerr, &std::cout, &result);
  }
  if (!status.ok()) return cli.Finish(status);
  switch (result.verdict()) {
    case tiltcal::proto::VerifyResult::HOLDS:
      return tiltcal::cli::kExitOk;
    case tiltcal::proto::VerifyResult::MOVED:
      return tiltcal::cli::kExitSuspect;
    default:
      return tiltcal::cli::kExitCannotTell;
  }
}

}  // namespace

int main(int argc, char** argv) {
  return tiltcal::cli::RunMain("tiltcal_verify", Main, argc, argv);
}
