// Acceptance on simulated sequences: tiltcal_simulate writes a real ROS1 bag
// and truth.txtpb (per-scan ground plane in the LiDAR frame at the stamp),
// tiltcal_decode reads the bag, tiltcal_ground fits the planes; the medians
// of the normal and height errors against the truth and the share of valid
// scans are checked, on flat and on tilted ground.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/geometry/angles.h"
#include "common/io/eigen_proto.h"
#include "common/io/record_stream.h"
#include "common/io/text_proto.h"
#include "tests/stages/ground/ground_test_util.h"
#include "tests/testing/synthetic_lidar.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/simulate_params.pb.h"
#include "tiltcal/proto/truth.pb.h"

namespace tiltcal {
namespace {

using testing::ToolPath;

double Median(std::vector<double> v) {
  if (v.empty()) return 1e9;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

void RunSequence(double roll_deg, double pitch_deg, const char* name) {
  for (const char* tool : {"tiltcal_simulate", "tiltcal_decode", "tiltcal_ground"}) {
    if (!testing::FileExists(ToolPath(tool))) {
      GTEST_SKIP() << ToolPath(tool) << " is not built";
    }
  }
  testing::TempDir dir;
  proto::SimulateParams scenario;
  const Status read = ReadTextProto(
      testing::SourceDir() + "/stages/simulate/scenarios/short_test_vlp16.txtpb", &scenario);
  ASSERT_TRUE(read.ok()) << read.message();
  scenario.set_ground_roll_deg(roll_deg);
  scenario.set_ground_pitch_deg(pitch_deg);
  scenario.set_num_threads(1);
  ASSERT_TRUE(WriteTextProto(dir.File("scenario.txtpb"), scenario).ok());

  std::string output;
  ASSERT_EQ(testing::RunCommand(ToolPath("tiltcal_simulate") + " --quiet --params=" +
                                    dir.File("scenario.txtpb") + " --out_bag=" +
                                    dir.File("run.bag") + " --out_truth=" +
                                    dir.File("truth.txtpb") + " --out_rig=" +
                                    dir.File("rig.txtpb"),
                                &output), 0) << output;
  ASSERT_EQ(testing::RunCommand(ToolPath("tiltcal_decode") + " --bag=" + dir.File("run.bag") +
                                    " --params=" + testing::SourceDir() +
                                    "/stages/decode/default_params.txtpb --rig=" +
                                    dir.File("rig.txtpb") + " --out_imu=" +
                                    dir.File("imu.binpb") + " --out_scans=" +
                                    dir.File("scans.binpb.lz4"),
                                &output), 0) << output;
  ASSERT_EQ(testing::RunCommand(ToolPath("tiltcal_ground") + " --imu=" + dir.File("imu.binpb") +
                                    " --scans=" + dir.File("scans.binpb.lz4") + " --rig=" +
                                    dir.File("rig.txtpb") + " --params=" + testing::SourceDir() +
                                    "/stages/ground/default_params.txtpb --out_ground=" +
                                    dir.File("ground.binpb"),
                                &output), 0) << output;
  std::printf("%s", output.c_str());

  proto::SimulationTruth truth;
  ASSERT_TRUE(ReadTextProto(dir.File("truth.txtpb"), &truth).ok());
  std::map<int64_t, const proto::TruthScan*> by_stamp;
  for (const proto::TruthScan& t : truth.scans()) by_stamp[t.stamp_ns()] = &t;
  std::vector<proto::GroundPlane> planes;
  ASSERT_TRUE(ReadAllRecords<proto::GroundPlane>(dir.File("ground.binpb"), &planes).ok());
  ASSERT_EQ(planes.size(), static_cast<size_t>(truth.scans_size()));

  std::vector<double> normal_deg, height_m;
  int valid = 0;
  for (const proto::GroundPlane& p : planes) {
    EXPECT_TRUE(testing::NoNan(p));
    const auto it = by_stamp.find(p.stamp_ns());
    ASSERT_NE(it, by_stamp.end()) << "no truth for stamp " << p.stamp_ns();
    if (!p.valid()) {
      std::printf("%s: scan %u rejected: %s\n", name, p.scan_index(), p.reject_detail().c_str());
      continue;
    }
    ++valid;
    const Eigen::Vector3d n_true = ToEigen(it->second->ground_normal_in_lidar());
    normal_deg.push_back(geometry::AngleBetweenDeg(testing::NormalOf(p), n_true));
    height_m.push_back(std::fabs(p.height_m() - it->second->ground_height_m()));
  }
  const double normal = Median(normal_deg), height = Median(height_m);
  const double share = static_cast<double>(valid) / planes.size();
  std::printf("%s: %zu scans, %.1f %% valid, median normal error %.4f deg, median height "
              "error %.2f mm\n", name, planes.size(), 100.0 * share, normal, 1e3 * height);
  EXPECT_LE(normal, 0.1);
  EXPECT_LE(height, 0.005);
  EXPECT_GE(share, 0.95);
}

TEST(GroundSimulated, FlatSequenceMatchesTruth) { RunSequence(0.0, 0.0, "flat"); }

TEST(GroundSimulated, TiltedSequenceMatchesTruth) { RunSequence(3.0, 8.0, "tilted"); }

}  // namespace
}  // namespace tiltcal
