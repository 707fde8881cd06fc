#include "stages/export/export.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <string>

#include <Eigen/Geometry>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/text_proto.h"
#include "stages/export/exported_calibration.h"
#include "stages/export/formats.h"
#include "tests/testing/test_env.h"

namespace tiltcal::exporter {
namespace {

using ::testing::HasSubstr;
using testing::RunCommand;
using testing::TempDir;
using testing::ToolPath;

// The known answer: C_bl = Rz(40°) Ry(-15°) Rx(25°), computed by hand (numpy)
// from roll 25°, pitch -15°, yaw 40°; r_b^{lb} = (0.12, -0.34, 0.56) m;
// τ = 12.3 ms. Every Euler angle is non-zero and distinct, so a transposed
// rotation, a swapped Euler order or a wrong direction changes the digits.
//   C_bl = [0.739942111694 -0.666354625021  0.091962954801
//           0.620885153015  0.623962871488 -0.474522878026
//           0.258819045103  0.408217893677  0.875426098066]
//   q_bl (w x y z) = 0.899907089822 0.245231085988 -0.046353699229 0.357603521684
//   r_l^{bl} = -C_bl^T r_b^{lb} = (-0.022630766636, 0.063507910849, -0.662611948022)
//   roll, pitch, yaw (rad) = 0.436332312999 -0.261799387799 0.698131700798
constexpr char kCalibrationText[] = R"pb(
imu_from_lidar {
  rotation { w: 0.899907089822004 x: 0.245231085988330 y: -0.046353699228730 z: 0.357603521684125 }
  translation { x: 0.12 y: -0.34 z: 0.56 }
}
time_offset_s: 0.0123
rotation_sigma_deg { x: 0.05 y: 0.06 z: 0.07 }
translation_sigma_m { x: 0.004 y: 0.005 z: 0.006 }
time_offset_sigma_s: 0.0002
verdict: WEAK
verdict_reasons: "translation along z taken from the rig"
)pb";

void WriteText(const std::string& path, const std::string& text) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fputs(text.c_str(), f);
  std::fclose(f);
}

class ExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    calibration_path_ = dir_.File("calibration.txtpb");
    WriteText(calibration_path_, kCalibrationText);
  }

  std::string Export(const std::string& format) {
    ExportOptions options;
    options.format = format;
    std::ostringstream out;
    const Status status = exporter::Run({calibration_path_, ""}, options, &out);
    EXPECT_TRUE(status.ok()) << status.message();
    return out.str();
  }

  TempDir dir_;
  std::string calibration_path_;
};

TEST_F(ExportTest, FastLioIsTheLidarInTheImuFrameWithTau) {
  const std::string text = Export("fast_lio");
  EXPECT_THAT(text, HasSubstr("time_offset_lidar_to_imu: 0.012300000\n"));
  EXPECT_THAT(text, HasSubstr("extrinsic_T: [ 0.120000000, -0.340000000, 0.560000000 ]\n"));
  EXPECT_THAT(text, HasSubstr("extrinsic_R: [ 0.739942112, -0.666354625, 0.091962955,\n"
                              "                   0.620885153, 0.623962871, -0.474522878,\n"
                              "                   0.258819045, 0.408217894, 0.875426098 ]\n"));
  EXPECT_THAT(text, HasSubstr("# verdict: WEAK\n#   translation along z taken from the rig\n"));
  EXPECT_THAT(text, HasSubstr("t_imu = t_lidar + tau"));
}

TEST_F(ExportTest, LioSamIsTheImuInTheLidarFrame) {
  const std::string text = Export("lio_sam");
  EXPECT_THAT(text, HasSubstr("extrinsicTrans: [ -0.022630767, 0.063507911, -0.662611948 ]\n"));
  const std::string c_lb =
      "[ 0.739942112, 0.620885153, 0.258819045,\n"
      "                  -0.666354625, 0.623962871, 0.408217894,\n"
      "                  0.091962955, -0.474522878, 0.875426098 ]\n";
  EXPECT_THAT(text, HasSubstr("extrinsicRot: " + c_lb));
  EXPECT_THAT(text, HasSubstr("extrinsicRPY: " + c_lb));
}

TEST_F(ExportTest, UrdfJointHasTheLidarAsChildWithFixedAxisRpy) {
  const std::string text = Export("urdf");
  EXPECT_THAT(text, HasSubstr("<parent link=\"imu_link\"/>\n  <child link=\"lidar_link\"/>\n"));
  EXPECT_THAT(text, HasSubstr("<origin xyz=\"0.120000000 -0.340000000 0.560000000\" "
                              "rpy=\"0.436332313 -0.261799388 0.698131701\"/>"));
}

TEST_F(ExportTest, TfRos1IsXyzYawPitchRollParentChild) {
  const std::string text = Export("tf_ros1");
  EXPECT_THAT(text, HasSubstr("\nrosrun tf2_ros static_transform_publisher 0.120000000 "
                              "-0.340000000 0.560000000 0.698131701 -0.261799388 0.436332313 "
                              "imu_link lidar_link\n"));
  EXPECT_THAT(text, HasSubstr("0.560000000 0.245231086 -0.046353699 0.357603522 0.899907090 "
                              "imu_link lidar_link\n"));
}

TEST_F(ExportTest, TfRos2UsesNamedArguments) {
  const std::string text = Export("tf_ros2");
  EXPECT_THAT(text, HasSubstr("\nros2 run tf2_ros static_transform_publisher --x 0.120000000 "
                              "--y -0.340000000 --z 0.560000000 --roll 0.436332313 "
                              "--pitch -0.261799388 --yaw 0.698131701 --frame-id imu_link "
                              "--child-frame-id lidar_link\n"));
}

TEST_F(ExportTest, KalibrHasBothDirectionsAndTimeshift) {
  const std::string text = Export("kalibr");
  EXPECT_THAT(text, HasSubstr("  T_imu_lidar:\n"
                              "  - [ 0.739942112, -0.666354625, 0.091962955, 0.120000000 ]\n"
                              "  - [ 0.620885153, 0.623962871, -0.474522878, -0.340000000 ]\n"
                              "  - [ 0.258819045, 0.408217894, 0.875426098, 0.560000000 ]\n"
                              "  - [ 0.000000000, 0.000000000, 0.000000000, 1.000000000 ]\n"));
  EXPECT_THAT(text, HasSubstr("  T_lidar_imu:\n"
                              "  - [ 0.739942112, 0.620885153, 0.258819045, -0.022630767 ]\n"));
  EXPECT_THAT(text, HasSubstr("  timeshift_lidar_imu: 0.012300000\n"));
  EXPECT_THAT(text, HasSubstr("  translation_sigma_m: [ 0.004000000, 0.005000000, 0.006000000 ]"));
}

TEST_F(ExportTest, MatrixHasBothDirectionsAndQuaternions) {
  const std::string text = Export("matrix");
  EXPECT_THAT(text, HasSubstr("x_imu = T_imu_lidar x_lidar\n"
                              "0.739942112 -0.666354625 0.091962955 0.120000000\n"));
  EXPECT_THAT(text, HasSubstr("x_lidar = T_lidar_imu x_imu\n"
                              "0.739942112 0.620885153 0.258819045 -0.022630767\n"));
  EXPECT_THAT(text, HasSubstr("0.899907090 0.245231086 -0.046353699 0.357603522\n"
                              "0.120000000 -0.340000000 0.560000000\n"));
  EXPECT_THAT(text, HasSubstr("0.899907090 -0.245231086 0.046353699 -0.357603522\n"
                              "-0.022630767 0.063507911 -0.662611948\n"));
}

TEST_F(ExportTest, JsonHasBothDirectionsSigmaAndVerdict) {
  const std::string text = Export("json");
  EXPECT_THAT(text, HasSubstr("\"quaternion_wxyz\": [0.899907090, 0.245231086, -0.046353699, "
                              "0.357603522]"));
  EXPECT_THAT(text, HasSubstr("\"translation_m\": [-0.022630767, 0.063507911, -0.662611948]"));
  EXPECT_THAT(text, HasSubstr("\"time_offset_s\": 0.012300000"));
  EXPECT_THAT(text, HasSubstr("\"verdict_reasons\": [\"translation along z taken from the rig\"]"));
}

// The rebuilt imu_from_lidar (16 numbers, row-major) and τ printed by a
// Python parser of the format; compared with the input.
void ExpectRoundTrip(const std::string& text, const std::string& parser, const TempDir& dir) {
  const std::string file = dir.File("exported.txt");
  const std::string script = dir.File("parse.py");
  WriteText(file, text);
  WriteText(script, std::string(R"py(
import json, math, shlex, sys
import numpy as np
def rpy(r, p, y):
    cx, sx, cy, sy, cz, sz = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx
def T(R, t):
    m = np.eye(4); m[:3, :3] = R; m[:3, 3] = t; return m
text = open(sys.argv[1]).read()
tau = float('nan')
)py") + parser + R"py(
print(' '.join(repr(float(v)) for v in list(m.reshape(-1)) + [tau]))
)py");
  std::string output;
  ASSERT_EQ(RunCommand(std::string(testing::kDebianPython) + " " + script + " " + file, &output), 0)
      << output;
  std::istringstream numbers(output);
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) ASSERT_TRUE(numbers >> m(i / 4, i % 4)) << output;
  double tau = 0;
  std::string tau_text;
  numbers >> tau_text;
  const Eigen::Matrix3d expected_rotation =
      Eigen::Quaterniond(0.899907089822004, 0.245231085988330, -0.046353699228730,
                         0.357603521684125)
          .normalized()
          .toRotationMatrix();
  EXPECT_LT((m.topLeftCorner<3, 3>() - expected_rotation).cwiseAbs().maxCoeff(), 2e-9) << output;
  EXPECT_LT((m.topRightCorner<3, 1>() - Eigen::Vector3d(0.12, -0.34, 0.56)).cwiseAbs().maxCoeff(),
            2e-9)
      << output;
  if (tau_text != "nan") {
    tau = std::stod(tau_text);
    EXPECT_NEAR(tau, 0.0123, 1e-12);
  }
}

class ExportRoundTripTest : public ExportTest {
 protected:
  void SetUp() override {
    ExportTest::SetUp();
    if (RunCommand(std::string(testing::kDebianPython) + " -c 'import yaml, numpy'") != 0) {
      GTEST_SKIP() << testing::kDebianPython << " has no yaml or numpy (python3-yaml, python3-numpy)";
    }
  }
};

TEST_F(ExportRoundTripTest, FastLio) {
  ExpectRoundTrip(Export("fast_lio"), R"py(
import yaml
y = yaml.safe_load(text)
m = T(np.array(y['mapping']['extrinsic_R']).reshape(3, 3), y['mapping']['extrinsic_T'])
tau = y['common']['time_offset_lidar_to_imu']
)py", dir_);
}

TEST_F(ExportRoundTripTest, LioSam) {
  ExpectRoundTrip(Export("lio_sam"), R"py(
import yaml
y = yaml.safe_load(text)['lio_sam']
C_lb = np.array(y['extrinsicRot']).reshape(3, 3)
assert np.allclose(C_lb, np.array(y['extrinsicRPY']).reshape(3, 3))
m = np.linalg.inv(T(C_lb, y['extrinsicTrans']))
)py", dir_);
}

TEST_F(ExportRoundTripTest, Kalibr) {
  ExpectRoundTrip(Export("kalibr"), R"py(
import yaml
y = yaml.safe_load(text)['lidar0']
m = np.array(y['T_imu_lidar'])
assert np.allclose(np.array(y['T_lidar_imu']) @ m, np.eye(4), atol=1e-8)
tau = y['timeshift_lidar_imu']
)py", dir_);
}

TEST_F(ExportRoundTripTest, Urdf) {
  ExpectRoundTrip(Export("urdf"), R"py(
import xml.etree.ElementTree as ET
joint = ET.fromstring(text)
assert joint.find('parent').get('link') == 'imu_link' and joint.find('child').get('link') == 'lidar_link'
origin = joint.find('origin')
m = T(rpy(*map(float, origin.get('rpy').split())), list(map(float, origin.get('xyz').split())))
)py", dir_);
}

TEST_F(ExportRoundTripTest, TfRos1) {
  ExpectRoundTrip(Export("tf_ros1"), R"py(
line = [l for l in text.splitlines() if l.startswith('rosrun')][0]
a = shlex.split(line)[3:]
assert a[6:] == ['imu_link', 'lidar_link']
x, y, z, yaw, pitch, roll = map(float, a[:6])
m = T(rpy(roll, pitch, yaw), [x, y, z])
)py", dir_);
}

TEST_F(ExportRoundTripTest, TfRos2) {
  ExpectRoundTrip(Export("tf_ros2"), R"py(
line = [l for l in text.splitlines() if l.startswith('ros2')][0]
a = shlex.split(line)[4:]
d = dict(zip(a[0::2], a[1::2]))
assert d['--frame-id'] == 'imu_link' and d['--child-frame-id'] == 'lidar_link'
m = T(rpy(float(d['--roll']), float(d['--pitch']), float(d['--yaw'])), [float(d['--' + k]) for k in 'xyz'])
)py", dir_);
}

TEST_F(ExportRoundTripTest, Json) {
  ExpectRoundTrip(Export("json"), R"py(
j = json.loads(text)
m = np.array(j['imu_from_lidar']['matrix'])
assert np.allclose(np.array(j['lidar_from_imu']['matrix']) @ m, np.eye(4), atol=1e-8)
tau = j['time_offset_s']
)py", dir_);
}

// --- the command line: refusals and bad input -------------------------------

int RunExport(const std::string& args, std::string* output) {
  return RunCommand(ToolPath("tiltcal_export") + " " + args, output);
}

// A drifting LiDAR clock: every format with comments says so in one comment
// line (the rate, tau at both ends, what to do); the numbers and JSON do not
// change.
TEST_F(ExportTest, ClockDriftIsACommentAndChangesNoNumber) {
  std::string before[8];
  const char* formats[] = {"fast_lio", "lio_sam", "urdf", "tf_ros1",
                           "tf_ros2",  "kalibr",  "matrix", "json"};
  for (int i = 0; i < 8; ++i) before[i] = Export(formats[i]);
  WriteText(calibration_path_, std::string(kCalibrationText) + R"pb(
time_offset_drift {
  estimated: true
  start_time_s: 0.1
  end_time_s: 160.1
  reference_time_s: 80.1
  rate_ppm: 50.0
  time_offset_start_s: 0.0163
  time_offset_end_s: 0.0083
}
)pb");
  const std::string line =
      "clock drift: the LiDAR clock runs +50.0 ppm against the IMU's: tau drifts -8.00 ms over "
      "160.0 s (from 16.30 ms at the start to 8.30 ms at the end); synchronise the clocks";
  for (int i = 0; i < 8; ++i) {
    const std::string text = Export(formats[i]);
    if (std::string(formats[i]) == "json") {
      EXPECT_EQ(text, before[i]);
      continue;
    }
    EXPECT_THAT(text, HasSubstr(line)) << formats[i];
    // Without that line the text is the one before.
    std::string without = text;
    const size_t at = without.find(line);
    const size_t line_start = without.rfind('\n', at) + 1;
    without.erase(line_start, without.find('\n', at) + 1 - line_start);
    EXPECT_EQ(without, before[i]) << formats[i];
  }
}

TEST_F(ExportTest, SuspectIsRefusedUnlessAllowed) {
  const std::string suspect = dir_.File("suspect.txtpb");
  std::string text = kCalibrationText;
  text.replace(text.find("verdict: WEAK"), 13, "verdict: SUSPECT");
  WriteText(suspect, text + "verdict_reasons: \"the map is no sharper than the rig's\"\n");
  std::string output;
  EXPECT_EQ(RunExport("--calibration=" + suspect + " --format=urdf --out=" + dir_.File("j.urdf"),
                      &output),
            1);
  EXPECT_EQ(output, "tiltcal_export: " + suspect +
                        ": verdict SUSPECT (translation along z taken from the rig); not exported "
                        "without --allow_suspect\n");
  EXPECT_FALSE(testing::FileExists(dir_.File("j.urdf")));
  EXPECT_EQ(RunExport("--calibration=" + suspect + " --format=urdf --allow_suspect", &output), 0);
  EXPECT_THAT(output, HasSubstr("verdict: SUSPECT\n    translation along z taken from the rig\n"
                                "    the map is no sharper than the rig's\n"));
}

TEST_F(ExportTest, BadInputIsOneLineNamingTheFile) {
  const std::string empty = dir_.File("empty.txtpb");
  const std::string garbage = dir_.File("garbage.txtpb");
  const std::string no_extrinsic = dir_.File("no_extrinsic.txtpb");
  WriteText(empty, "");
  WriteText(garbage, "this is { not a calibration");
  WriteText(no_extrinsic, "time_offset_s: 0.01\n");
  const std::string out = dir_.File("out.yaml");
  for (const std::string& file :
       {dir_.File("missing.txtpb"), empty, garbage, no_extrinsic}) {
    std::string output;
    EXPECT_EQ(RunExport("--calibration=" + file + " --format=kalibr --out=" + out, &output), 1)
        << file;
    EXPECT_THAT(output, HasSubstr(file)) << file;
    EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;
    EXPECT_FALSE(testing::FileExists(out)) << file;
  }
  std::string output;
  EXPECT_EQ(RunExport("--calibration=" + no_extrinsic + " --format=kalibr", &output), 1);
  EXPECT_EQ(output, "tiltcal_export: " + no_extrinsic +
                        ": no imu_from_lidar (not a calibration.txtpb?)\n");
}

TEST_F(ExportTest, UnknownFormatIsAUsageError) {
  std::string output;
  EXPECT_EQ(RunExport("--calibration=" + calibration_path_ + " --format=yaml", &output), 2);
  EXPECT_THAT(output, HasSubstr("unknown --format=yaml (one of: fast_lio, lio_sam, urdf, "
                                "tf_ros1, tf_ros2, kalibr, matrix, json"));
  EXPECT_EQ(RunExport("--calibration=" + calibration_path_ + " --format=urdf --imu_frame='a b'",
                      &output),
            1);
  EXPECT_THAT(output, HasSubstr("--imu_frame=\"a b\" has the character ' '"));
}

TEST_F(ExportTest, OutFileHoldsWhatStdoutWould) {
  const std::string out = dir_.File("fast_lio.yaml");
  std::string output;
  ASSERT_EQ(RunExport("--calibration=" + calibration_path_ + " --format=fast_lio --out=" + out,
                      &output),
            0)
      << output;
  std::string written;
  ASSERT_TRUE(ReadFileToString(out, &written).ok());
  EXPECT_EQ(written, Export("fast_lio"));
}

}  // namespace
}  // namespace tiltcal::exporter
