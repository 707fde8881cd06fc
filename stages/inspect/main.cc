// tiltcal_inspect: looks into any file of the pipeline.
//   tiltcal_inspect info FILE
//   tiltcal_inspect cat  FILE [--from=N] [--count=K] [--single_line]
//   tiltcal_inspect csv  FILE [--points --record=N] [--field=NAME]
#include <iostream>

#include <gflags/gflags.h>

#include "stages/inspect/ground_summary.h"
#include "stages/inspect/inspect.h"
#include "stages/inspect/pcd_export.h"

DEFINE_int64(from, 0, "cat: first record to print");
DEFINE_int64(count, -1, "cat: number of records to print (-1: all)");
DEFINE_bool(single_line, false, "cat: one record per line");
DEFINE_bool(points, false, "csv: print the points of scan --record");
DEFINE_int64(record, 0, "csv --points / pcd: index of the scan");
DEFINE_string(ground, "", "pcd: ground.binpb whose point masks label the points");
DEFINE_string(out, "", "pcd: the PCD file to write");
DEFINE_string(field, "", "csv of a text file: the repeated field to tabulate");

int main(int argc, char** argv) {
  gflags::SetUsageMessage(
      "looks into any tiltcal file\n"
      "  tiltcal_inspect info FILE\n"
      "  tiltcal_inspect cat FILE [--from=N] [--count=K] [--single_line]\n"
      "  tiltcal_inspect csv FILE [--points --record=N] [--field=NAME]\n"
      "  tiltcal_inspect pcd SCANS --record=N [--ground=ground.binpb] --out=scan.pcd");
  gflags::ParseCommandLineFlags(&argc, &argv, /*remove_flags=*/true);
  if (argc != 3) {
    std::cerr << "usage: tiltcal_inspect info|cat|csv|pcd FILE (see --help)\n";
    return 2;
  }
  const std::string command = argv[1];
  const std::string path = argv[2];
  std::ios::sync_with_stdio(false);
  tiltcal::Status status;
  if (command == "info") {
    status = tiltcal::inspect::RunInfo(path, std::cout);
  } else if (command == "cat") {
    status = tiltcal::inspect::RunCat(path, {FLAGS_from, FLAGS_count, FLAGS_single_line},
                                      std::cout);
  } else if (command == "csv") {
    status = tiltcal::inspect::RunCsv(path, {FLAGS_points, FLAGS_record, FLAGS_field}, std::cout);
    // ground.binpb: rejected scans by reason on stderr (the table stays clean).
    if (status.ok() && !FLAGS_points) {
      status = tiltcal::inspect::PrintGroundSummary(path, std::cerr);
    }
  } else if (command == "pcd") {
    status = tiltcal::inspect::RunPcd(path, {FLAGS_record, FLAGS_ground, FLAGS_out}, std::cerr);
  } else {
    std::cerr << "tiltcal_inspect: unknown command '" << command << "' (info, cat, csv, pcd)\n";
    return 2;
  }
  std::cout.flush();
  if (!status.ok()) {
    std::cerr << "tiltcal_inspect: " << status.message() << "\n";
    return 1;
  }
  return 0;
}
