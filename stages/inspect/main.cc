// tiltcal_inspect: looks into any file of the pipeline.
#include <cerrno>
#include <cstring>
#include <iostream>
#include <string>

#include "common/cli/command_line.h"
#include "common/io/params.h"
#include "stages/inspect/bag_info.h"
#include "stages/inspect/bag_info_report.h"
#include "stages/inspect/check.h"
#include "stages/inspect/default_params_text.h"
#include "stages/inspect/ground_summary.h"
#include "stages/inspect/inspect.h"
#include "stages/inspect/pcd_export.h"
#include "stages/inspect/rig_draft.h"

namespace {

using tiltcal::Status;
using tiltcal::cli::CommandLine;

// Flushes std::cout: a table cut short (a full disk behind `> ground.csv`)
// is a failure, not exit 0.
Status FlushStdout() {
  std::cout.flush();
  if (std::cout) return Status::Ok();
  return Status::Error(std::string("standard output: cannot write: ") + std::strerror(errno));
}

// `check --bag=... [--rig=...] [--params=...]`: the pre-flight check of a bag.
Status RunCheckCommand(const CommandLine& cli) {
  tiltcal::proto::CheckParams params;
  TILTCAL_RETURN_IF_ERROR(tiltcal::LoadParamsOrDefaults(
      cli.Get("params"), tiltcal::inspect::DefaultParamsText(), &params));
  return tiltcal::inspect::RunCheck({cli.Get("bag"), cli.Get("rig")}, params, std::cout);
}

// `rig --bag=... [--out=rig.txtpb] [--params=...]`: a rig drafted from a bag.
Status RunRigCommand(const CommandLine& cli) {
  tiltcal::proto::CheckParams params;
  TILTCAL_RETURN_IF_ERROR(tiltcal::LoadParamsOrDefaults(
      cli.Get("params"), tiltcal::inspect::DefaultParamsText(), &params));
  return tiltcal::inspect::RunRigDraft({cli.Get("bag"), cli.Get("out")}, params, std::cout,
                                       std::cerr);
}

// `info --bag=... [--format=text|json]`: what a bag holds.
Status RunBagInfoCommand(const CommandLine& cli) {
  tiltcal::inspect::BagInfo info;
  TILTCAL_RETURN_IF_ERROR(tiltcal::inspect::ReadBagInfo(cli.Get("bag"), &info));
  if (cli.Get("format") == "json") {
    tiltcal::inspect::WriteBagInfoJson(info, std::cout);
  } else {
    tiltcal::inspect::WriteBagInfoText(info, std::cout);
  }
  return Status::Ok();
}

Status RunCommand(const CommandLine& cli, const std::string& command, const std::string& path) {
  namespace inspect = tiltcal::inspect;
  int64_t from = 0, count = 0, record = 0;
  TILTCAL_RETURN_IF_ERROR(cli.GetInt("from", &from));
  TILTCAL_RETURN_IF_ERROR(cli.GetInt("count", &count));
  TILTCAL_RETURN_IF_ERROR(cli.GetInt("record", &record));
  if (command == "info") return inspect::RunInfo(path, std::cout);
  if (command == "cat") {
    return inspect::RunCat(path, {from, count, cli.GetSwitch("single_line")}, std::cout);
  }
  if (command == "csv") {
    const bool points = cli.GetSwitch("points");
    TILTCAL_RETURN_IF_ERROR(inspect::RunCsv(path, {points, record, cli.Get("field")}, std::cout));
    TILTCAL_RETURN_IF_ERROR(FlushStdout());
    // ground.binpb: rejected scans by reason on stderr (the table stays clean).
    return points ? Status::Ok() : inspect::PrintGroundSummary(path, std::cerr);
  }
  return inspect::RunPcd(path, {record, cli.Get("ground"), cli.Get("out")}, std::cerr);
}

}  // namespace

namespace {

int Main(int argc, char** argv) {
  CommandLine cli("tiltcal_inspect",
                  "looks into a bag before you calibrate (info --bag, check, rig) and into any "
                  "file of the pipeline (info, cat, csv, pcd)");
  cli.SetPositional("info|cat|csv|pcd FILE  or  info|check|rig --bag=BAG",
                    "info: what the file is; cat: its records as text; csv: a table; "
                    "pcd: one scan as a PCD file; info --bag: what a bag holds (format, "
                    "compression, every topic with its type, count, encoding, rate and span; "
                    "a rosbag2 bag's metadata.yaml beside it, disagreements as warnings; "
                    "--format); check: the pre-flight check of a bag (--bag, --rig, "
                    "--params; exit 1 when it cannot be calibrated); rig: a rig.txtpb "
                    "drafted from a bag (--bag, --out, --params)",
                    1, 2);
  cli.AddFlag("from", "cat: first record to print", tiltcal::cli::kOptional, "0");
  cli.AddFlag("count", "cat: number of records to print (-1: all)", tiltcal::cli::kOptional,
              "-1");
  cli.AddSwitch("single_line", "cat: one record per line");
  cli.AddSwitch("points", "csv: print the points of scan --record");
  cli.AddFlag("record", "csv --points / pcd: index of the scan", tiltcal::cli::kOptional, "0");
  cli.AddFlag("field", "csv of a text file: the repeated field to tabulate");
  cli.AddFlag("ground", "pcd: ground.binpb whose point masks label the points");
  cli.AddFlag("out", "pcd: the PCD file to write; rig: the rig to write (default: stdout)");
  cli.AddFlag("bag",
              "info, check, rig: the bag to look at (.bag, .mcap, .db3, a rosbag2 folder or a "
              "folder of bag files)");
  cli.AddFlag("format", "info --bag: text or json", tiltcal::cli::kOptional, "text");
  cli.AddFlag("rig", "check, optional: rig.txtpb (topics, extrinsic for up, imu_height_m)");
  cli.AddFlag("params",
              "check, rig, optional: check params, text format (default: "
              "stages/inspect/default_params.txtpb, compiled in)");
  cli.AddExample("tiltcal_inspect check --bag=datasets/husky/run1.bag "
                 "--rig=datasets/husky/rig.txtpb");
  cli.AddExample("tiltcal_inspect rig --bag=datasets/husky/run1.bag "
                 "--out=datasets/husky/rig.txtpb");
  cli.AddExample("tiltcal_inspect info --bag=datasets/husky/run1.bag");
  cli.AddExample("tiltcal_inspect info --bag=datasets/husky/run2 --format=json");
  cli.AddExample("tiltcal_inspect info out/run1/scans.binpb.lz4");
  cli.AddExample("tiltcal_inspect csv out/run1/ground.binpb > ground.csv");
  cli.AddExample("tiltcal_inspect csv out/run1/scans.binpb.lz4 --points --record=10");
  cli.AddExample(
      "tiltcal_inspect pcd out/run1/scans.binpb.lz4 --record=10 --ground=out/run1/ground.binpb "
      "--out=scan10.pcd");
  if (const auto exit_code = cli.Parse(argc, argv)) return *exit_code;
  const std::string& command = cli.positional()[0];
  if (command != "info" && command != "cat" && command != "csv" && command != "pcd" &&
      command != "check" && command != "rig") {
    std::cerr << "tiltcal_inspect: unknown command '" << command
              << "' (info, cat, csv, pcd, check, rig; see tiltcal_inspect --help)\n";
    return tiltcal::cli::kExitUsage;
  }
  // check and rig take --bag; info takes --bag or a FILE.
  const bool bag_info = command == "info" && !cli.Get("bag").empty();
  const bool check = command == "check" || command == "rig" || bag_info;
  if (cli.positional().size() != (check ? 1u : 2u) || (check && cli.Get("bag").empty())) {
    std::cerr << "tiltcal_inspect: " << command
              << (check ? " takes --bag=FILE and no FILE argument"
                  : command == "info" ? " needs one FILE or --bag=BAG"
                                      : " needs one FILE")
              << " (see --help)\n";
    return tiltcal::cli::kExitUsage;
  }
  if (cli.Get("format") != "text" && cli.Get("format") != "json") {
    std::cerr << "tiltcal_inspect: --format=" << cli.Get("format") << ": expected text or json\n";
    return tiltcal::cli::kExitUsage;
  }
  std::ios::sync_with_stdio(false);
  Status status = command == "check" ? RunCheckCommand(cli)
                  : command == "rig" ? RunRigCommand(cli)
                  : bag_info         ? RunBagInfoCommand(cli)
                                     : RunCommand(cli, command, cli.positional()[1]);
  if (status.ok()) status = FlushStdout();
  return cli.Finish(status);
}

}  // namespace

int main(int argc, char** argv) {
  return tiltcal::cli::RunMain("tiltcal_inspect", Main, argc, argv);
}
