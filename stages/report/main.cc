// tiltcal_report: repeatability of the calibrations of a dataset.
//   tiltcal_report --out=out/repeatability.txt [--out_csv=out/repeatability.csv]
//                  [--rig=DATASET/rig.txtpb] [--title=TEXT] out/seq1 out/seq2 ...
// Each directory holds calibration.txtpb and, for simulated data, truth.txtpb.
#include <iostream>

#include <gflags/gflags.h>

#include "stages/report/report.h"

DEFINE_string(out, "", "output: the repeatability table (text)");
DEFINE_string(out_csv, "", "output: the same as CSV (optional)");
DEFINE_string(rig, "", "input: the dataset's rig.txtpb, for the measured extrinsic (optional)");
DEFINE_string(title, "", "first line of the table");

int main(int argc, char** argv) {
  gflags::SetUsageMessage(
      "repeatability over calibrations\n"
      "  tiltcal_report --out=TABLE [--out_csv=CSV] [--rig=RIG] SEQUENCE_DIR...");
  gflags::ParseCommandLineFlags(&argc, &argv, /*remove_flags=*/true);
  if (FLAGS_out.empty() || argc < 2) {
    std::cerr << "usage: tiltcal_report --out=TABLE [--out_csv=CSV] [--rig=RIG] SEQUENCE_DIR...\n";
    return 2;
  }
  tiltcal::report::RunOptions options;
  options.sequence_dirs.assign(argv + 1, argv + argc);
  options.rig_path = FLAGS_rig;
  options.out_table_path = FLAGS_out;
  options.out_csv_path = FLAGS_out_csv;
  options.title = FLAGS_title;
  std::string table;
  const tiltcal::Status status = tiltcal::report::Run(options, &table);
  if (!status.ok()) {
    std::cerr << "tiltcal_report: " << status.message() << "\n";
    return 1;
  }
  std::cout << table;
  return 0;
}
