// A simulated Livox Mid-360 sequence (non-repetitive pattern written as
// livox_ros_driver/CustomMsg, noise-tagged returns, built-in IMU in g)
// through the command-line pipeline as a user runs it: tiltcal_simulate ->
// tiltcal_decode -> tiltcal_ground -> tiltcal_calibrate. Nothing downstream
// of decode may assume a ring order: every ground plane must match the
// simulator's truth and the extrinsic and time offset must be recovered
// within the tolerances of the VLP-16 sequence it is made from
// (calibrate_pipeline_test, short_flat_vlp16.txtpb). A short Avia sequence
// (forward-looking rosette) on tilted ground checks decode and ground only.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "common/geometry/angles.h"
#include "common/io/eigen_proto.h"
#include "common/io/record_stream.h"
#include "common/io/text_proto.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/calibration.pb.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/scan.pb.h"

#include "tiltcal/proto/truth.pb.h"

namespace tiltcal {
namespace {

using testing::ToolPath;

// Runs the commands in turn; false (and a failure recorded) when one fails.
bool RunAll(const std::vector<std::string>& commands) {
  for (const std::string& command : commands) {
    std::string output;
    if (testing::RunCommand(command + " 2>&1", &output) != 0) {
      ADD_FAILURE() << command << "\n" << output;
      return false;
    }
  }
  return true;
}

// Simulates `scenario` (text, a SimulateParams) into dir, decodes it and
// runs tiltcal_ground with `ground_params` ("" = defaults).
bool SimulateDecodeGround(const testing::TempDir& dir, const std::string& scenario,
                          const std::string& ground_params) {
  for (const char* tool : {"tiltcal_simulate", "tiltcal_decode", "tiltcal_ground"}) {
    if (!testing::FileExists(ToolPath(tool))) {
      ADD_FAILURE() << "build " << tool << " first";
      return false;
    }
  }
  std::ofstream(dir.File("scenario.txtpb")) << scenario;
  return RunAll({ToolPath("tiltcal_simulate") + " --quiet --params=" + dir.File("scenario.txtpb") +
                     " --out_bag=" + dir.File("s.bag") + " --out_truth=" +
                     dir.File("truth.txtpb") + " --out_rig=" + dir.File("rig.txtpb"),
                 ToolPath("tiltcal_decode") + " --bag=" + dir.File("s.bag") + " --rig=" +
                     dir.File("rig.txtpb") + " --out_imu=" + dir.File("imu.binpb") +
                     " --out_scans=" + dir.File("scans.binpb.lz4"),
                 ToolPath("tiltcal_ground") + " --imu=" + dir.File("imu.binpb") + " --scans=" +
                     dir.File("scans.binpb.lz4") + " --rig=" + dir.File("rig.txtpb") +
                     (ground_params.empty() ? "" : " --params=" + ground_params) +
                     " --out_ground=" + dir.File("ground.binpb")});
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// `text` with `from` replaced by `to` (a failure when `from` is absent).
std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "'" << from << "' not found";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// Checks the decoded scans (Livox point times, lines up to max_line
// interleaved point by point, noise dropped) and every valid ground plane
// against the truth of its scan; at least min_valid_fraction valid.
void ExpectScansAndGroundMatchTruth(const testing::TempDir& dir, const char* label,
                                    uint32_t max_line, double min_valid_fraction) {
  proto::SimulationTruth truth;
  ASSERT_TRUE(ReadTextProto(dir.File("truth.txtpb"), &truth).ok());
  std::vector<proto::Scan> scans;
  ASSERT_TRUE(ReadAllRecords<proto::Scan>(dir.File("scans.binpb.lz4"), &scans).ok());
  ASSERT_EQ(scans.size(), static_cast<size_t>(truth.scans_size()));
  uint64_t noise = 0;
  int64_t ring_changes = 0, points = 0;
  for (const proto::Scan& scan : scans) {
    EXPECT_EQ(scan.time_source(), proto::POINT_TIME_LIVOX_CUSTOM_MSG);
    noise += scan.num_dropped_noise_tag();
    points += scan.ring_size();
    for (int i = 1; i < scan.ring_size(); ++i) ring_changes += scan.ring(i) != scan.ring(i - 1);
    EXPECT_LE(*std::max_element(scan.ring().begin(), scan.ring().end()), max_line);
  }
  EXPECT_GT(noise, 1000u) << label;
  EXPECT_GT(ring_changes, points / 2) << label << ": lines not interleaved";

  std::vector<proto::GroundPlane> planes;
  ASSERT_TRUE(ReadAllRecords<proto::GroundPlane>(dir.File("ground.binpb"), &planes).ok());
  ASSERT_EQ(planes.size(), scans.size());
  int valid = 0;
  double worst_normal_deg = 0.0, worst_height_cm = 0.0;
  for (size_t k = 0; k < planes.size(); ++k) {
    if (!planes[k].valid()) continue;
    ++valid;
    const proto::TruthScan& t = truth.scans(static_cast<int>(k));
    ASSERT_EQ(planes[k].stamp_ns(), t.stamp_ns());
    worst_normal_deg =
        std::max(worst_normal_deg, geometry::AngleBetweenDeg(ToEigen(planes[k].normal_in_lidar()),
                                                             ToEigen(t.ground_normal_in_lidar())));
    worst_height_cm =
        std::max(worst_height_cm, std::abs(planes[k].height_m() - t.ground_height_m()) * 100);
  }
  std::printf("%s: %d / %zu ground planes valid, worst normal %.3f deg, height %.2f cm, "
              "%llu noise points dropped\n",
              label, valid, planes.size(), worst_normal_deg, worst_height_cm,
              static_cast<unsigned long long>(noise));
  EXPECT_GE(valid, static_cast<int>(planes.size() * min_valid_fraction)) << label;
  EXPECT_LT(worst_normal_deg, 0.5) << label;
  EXPECT_LT(worst_height_cm, 2.0) << label;
}

// The forward-looking Avia (70 deg of azimuth) on tilted ground: its planes
// cover a fifth of the azimuth, so the ground params accept a coverage of 0.1.
TEST(LivoxPipelineTest, AviaTiltedGroundPlanesAgainstTruth) {
  testing::TempDir dir;
  const std::string src = testing::SourceDir();
  std::string scenario = ReadText(src + "/stages/simulate/scenarios/short_test_vlp16.txtpb");
  scenario = Replace(scenario, "model: VLP_16", "model: LIVOX_AVIA");
  scenario = Replace(scenario, "append_surface_label: true", "livox_noise_fraction: 0.02");
  std::ofstream(dir.File("ground_params.txtpb"))
      << Replace(ReadText(src + "/stages/ground/default_params.txtpb"),
                 "min_azimuth_coverage: 0.25", "min_azimuth_coverage: 0.1");
  ASSERT_TRUE(SimulateDecodeGround(dir, scenario, dir.File("ground_params.txtpb")));
  ExpectScansAndGroundMatchTruth(dir, "Avia", 5, 0.95);
}

TEST(LivoxPipelineTest, Mid360SequenceGroundAndCalibrationAgainstTruth) {
  ASSERT_TRUE(testing::FileExists(ToolPath("tiltcal_calibrate"))) << "build tiltcal_calibrate";
  testing::TempDir dir;
  ASSERT_TRUE(SimulateDecodeGround(
      dir, ReadText(testing::SourceDir() + "/tests/stages/calibrate/short_flat_mid360.txtpb"),
      ""));
  ExpectScansAndGroundMatchTruth(dir, "Mid-360", 3, 0.95);
  ASSERT_TRUE(RunAll({ToolPath("tiltcal_calibrate") + " --imu=" + dir.File("imu.binpb") +
                      " --scans=" + dir.File("scans.binpb.lz4") + " --ground=" +
                      dir.File("ground.binpb") + " --rig=" + dir.File("rig.txtpb") +
                      " --out=" + dir.File("calibration.txtpb")}));
  proto::SimulationTruth truth;
  ASSERT_TRUE(ReadTextProto(dir.File("truth.txtpb"), &truth).ok());

  // Calibration, with the error split as in calibrate_pipeline_test.
  proto::CalibrationResult result;
  ASSERT_TRUE(ReadTextProto(dir.File("calibration.txtpb"), &result).ok());
  const Rigid3d est = ToEigen(result.imu_from_lidar());
  const Rigid3d tru = ToEigen(truth.imu_from_lidar());
  const Eigen::Vector3d up_b = -ToEigen(truth.gravity_in_world()).normalized();
  const Eigen::Vector3d dt = est.translation - tru.translation;
  const double planar_cm = (dt - dt.dot(up_b) * up_b).norm() * 100.0;
  const Eigen::AngleAxisd err(est.rotation * tru.rotation.conjugate());
  const Eigen::Vector3d phi = err.angle() * err.axis();
  const double yaw_deg = geometry::RadToDeg(std::abs(phi.dot(up_b)));
  const double tilt_deg = geometry::RadToDeg((phi - phi.dot(up_b) * up_b).norm());
  const double tau_ms = std::abs(result.time_offset_s() - truth.time_offset_s()) * 1e3;
  std::printf("Mid-360 calibration: tilt %.4f deg, yaw %.4f deg, planar %.3f cm, vertical "
              "%.3f cm, tau %.3f ms, verdict %s\n",
              tilt_deg, yaw_deg, planar_cm, dt.dot(up_b) * 100.0, tau_ms,
              proto::CalibrationResult::Verdict_Name(result.verdict()).c_str());
  EXPECT_LT(tilt_deg, 0.05);
  EXPECT_LT(yaw_deg, 0.25);
  EXPECT_LT(planar_cm, 1.5);
  EXPECT_LT(tau_ms, 0.5);
  EXPECT_EQ(result.verdict(), proto::CalibrationResult::OK);
}

}  // namespace
}  // namespace tiltcal
