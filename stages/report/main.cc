// tiltcal_report: repeatability of the calibrations of a dataset.
#include <iostream>

#include "common/cli/command_line.h"
#include "common/io/params.h"
#include "stages/report/default_params_text.h"
#include "stages/report/report.h"

namespace {

int Main(int argc, char** argv) {
  tiltcal::cli::CommandLine cli("tiltcal_report",
                                "repeatability over the calibrations of a dataset (SO(3) mean, "
                                "sigma per component, errors against a simulation truth) and the "
                                "dataset's page report.html");
  cli.SetPositional("SEQUENCE_DIR...",
                    "out/<sequence> folders, each with calibration.txtpb (+ truth.txtpb)", 1, -1);
  cli.AddFlag("out", "output: the repeatability table (text)", tiltcal::cli::kRequired);
  cli.AddFlag("out_csv", "output: the same as CSV");
  cli.AddFlag("out_html", "output: the dataset's page (self-contained HTML)");
  cli.AddFlag("rig", "input: the dataset's rig.txtpb, for the measured extrinsic row");
  cli.AddFlag("title", "first line of the table");
  cli.AddFlag("params",
              "input: params, text format (default: stages/report/default_params.txtpb, "
              "compiled in)");
  cli.AddFlag("dataset_calibration",
              "input: the dataset's calibration.txtpb (tiltcal_dataset_calibration), for the joint "
              "row and the consistency column");
  cli.AddFlag("verify",
              "input: out/verify.txtpb (tiltcal_verify), for the page's section on the check "
              "against a stored calibration");
  cli.AddExample(
      "tiltcal_report --out=out/repeatability.txt --out_csv=out/repeatability.csv "
      "--out_html=out/report.html "
      "--rig=datasets/husky/rig.txtpb out/run1 out/run2");
  if (const auto exit_code = cli.Parse(argc, argv)) return *exit_code;
  tiltcal::report::ReportPaths paths;
  paths.sequence_dirs = cli.positional();
  paths.rig = cli.Get("rig");
  paths.out = cli.Get("out");
  paths.out_csv = cli.Get("out_csv");
  paths.out_html = cli.Get("out_html");
  paths.title = cli.Get("title");
  paths.dataset_calibration = cli.Get("dataset_calibration");
  paths.verify = cli.Get("verify");
  tiltcal::proto::ReportParams params;
  const tiltcal::Status status = tiltcal::LoadParamsOrDefaults(
      cli.Get("params"), tiltcal::report::DefaultParamsText(), &params);
  if (!status.ok()) return cli.Finish(status);
  return cli.Finish(tiltcal::report::Run(paths, params, &std::cout));
}

}  // namespace

int main(int argc, char** argv) {
  return tiltcal::cli::RunMain("tiltcal_report", Main, argc, argv);
}
