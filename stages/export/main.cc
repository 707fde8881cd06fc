// tiltcal_export: a calibration in the conventions of the tools that use it.
#include <iostream>

#include "common/cli/command_line.h"
#include "stages/export/export.h"
#include "stages/export/formats.h"

namespace {

int Main(int argc, char** argv) {
  using tiltcal::cli::kRequired;
  tiltcal::cli::CommandLine cli(
      "tiltcal_export",
      "the LiDAR-IMU extrinsic and time offset of a calibration.txtpb, ready to paste");
  cli.AddFlag("calibration",
              "input: a calibration.txtpb, the dataset's (out/calibration.txtpb) or a "
              "sequence's (out/<sequence>/calibration.txtpb)",
              kRequired);
  cli.AddFlag("format", "output format: " + tiltcal::exporter::ExportFormatNames(), kRequired);
  cli.AddFlag("out", "output file (default: stdout)");
  cli.AddFlag("imu_frame", "name of the IMU frame/link", tiltcal::cli::kOptional, "imu_link");
  cli.AddFlag("lidar_frame", "name of the LiDAR frame/link", tiltcal::cli::kOptional,
              "lidar_link");
  cli.AddSwitch("allow_suspect",
                "export a calibration whose verdict is SUSPECT (refused, exit 1, without it)");
  cli.AddExample("tiltcal_export --calibration=out/run1/calibration.txtpb --format=fast_lio");
  cli.AddExample(
      "tiltcal_export --calibration=out/run1/calibration.txtpb --format=urdf "
      "--imu_frame=imu_link --lidar_frame=velodyne --out=lidar_joint.urdf");
  if (const auto exit_code = cli.Parse(argc, argv)) return *exit_code;
  if (tiltcal::exporter::FindExportFormat(cli.Get("format")) == nullptr) {
    std::cerr << "tiltcal_export: unknown --format=" << cli.Get("format") << " (one of: "
              << tiltcal::exporter::ExportFormatNames() << "; see --help)\n";
    return tiltcal::cli::kExitUsage;
  }
  tiltcal::exporter::ExportPaths paths;
  paths.calibration = cli.Get("calibration");
  paths.out = cli.Get("out");
  tiltcal::exporter::ExportOptions options;
  options.format = cli.Get("format");
  options.allow_suspect = cli.GetSwitch("allow_suspect");
  options.imu_frame = cli.Get("imu_frame");
  options.lidar_frame = cli.Get("lidar_frame");
  return cli.Finish(tiltcal::exporter::Run(paths, options, &std::cout));
}

}  // namespace

int main(int argc, char** argv) {
  return tiltcal::cli::RunMain("tiltcal_export", Main, argc, argv);
}
