// The exports keep every string of their input as data: a calibration file
// whose path and verdict reasons carry newlines, a carriage return, an
// escape, U+2028, HTML, "-->", shell commands and YAML keys. Each format is
// read by its consumer's parser (sh with stand-in rosrun / ros2, PyYAML,
// xml.etree, json, the matrix rows) and must give the calibration's values
// and nothing else.
#include <filesystem>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/io/atomic_file.h"
#include "stages/export/export.h"
#include "tests/testing/test_env.h"

namespace tiltcal::exporter {
namespace {

using ::testing::HasSubstr;
using testing::RunCommand;

// A folder and reasons that end a comment line if a writer lets them.
constexpr char kFolder[] = "a,b\n$(touch PWNED)\ntouch PWNED\r\nextra: 1\x1b\xe2\x80\xa8more: 2";
constexpr char kReasonLines[] =
    "line one\ntouch PWNED; echo\r\nextra_key: 1\x01\xe2\x80\xa8" "also_key: 2\xc2\x85key3: 3";
constexpr char kReasonMarkup[] = "--> <joint name=\"x\"/> <!-- \"><img src=x onerror=alert(1)>";

class ExportInjectionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::filesystem::create_directories(dir_.File(kFolder));
    calibration_ = dir_.File(kFolder) + "/calibration.txtpb";
    ASSERT_TRUE(WriteFileAtomically(calibration_,
                                    "imu_from_lidar { rotation { w: 0.9 x: 0.1 y: 0.2 z: 0.3 } "
                                    "translation { x: 0.12 y: -0.34 z: 0.56 } }\n"
                                    "time_offset_s: 0.0123\nverdict: SUSPECT\n"
                                    "verdict_reasons: \"line one\\ntouch PWNED; echo\\r\\n"
                                    "extra_key: 1\\001\\342\\200\\250also_key: 2\\302\\205key3: 3\"\n"
                                    "verdict_reasons: \"--> <joint name=\\\"x\\\"/> <!-- \\\">"
                                    "<img src=x onerror=alert(1)>\"\n")
                    .ok());
    std::filesystem::create_directories(dir_.File("bin"));
    // Stand-ins that record their arguments, one per line, and a mark per call.
    for (const char* tool : {"rosrun", "ros2"}) {
      ASSERT_TRUE(WriteFileAtomically(dir_.File(std::string("bin/") + tool),
                                      "#!/bin/sh\nfor a; do printf '%s\\n' \"$a\"; done >> "
                                      "calls.txt\necho CALL_END >> calls.txt\n")
                      .ok());
      std::filesystem::permissions(dir_.File(std::string("bin/") + tool),
                                   std::filesystem::perms::owner_all);
    }
  }

  std::string Export(const std::string& format) {
    ExportOptions options;
    options.format = format;
    options.allow_suspect = true;
    std::ostringstream out;
    const Status status = exporter::Run({calibration_, ""}, options, &out);
    EXPECT_TRUE(status.ok()) << status.message();
    return out.str();
  }

  // Runs the Python `check` with `text` in the variable text and the
  // expected reasons and source in `reasons` and `source`; "ok" expected.
  void ExpectPython(const std::string& text, const std::string& check) {
    const std::string file = dir_.File("exported.txt");
    ASSERT_TRUE(WriteFileAtomically(file, text).ok());
    const std::string script = dir_.File("check.py");
    ASSERT_TRUE(WriteFileAtomically(
                    script, "import json, sys, xml.etree.ElementTree as ET\n"
                            "text = open(sys.argv[1], encoding='utf-8', newline='').read()\n"
                            "source = " + std::string("bytes.fromhex('") + Hex(calibration_) +
                                "').decode()\n"
                                "reasons = [bytes.fromhex('" + Hex(kReasonLines) +
                                "').decode(), bytes.fromhex('" + Hex(kReasonMarkup) +
                                "').decode()]\n" + check + "\nprint('ok')\n")
                    .ok());
    std::string output;
    EXPECT_EQ(RunCommand(std::string(testing::kDebianPython) + " " + script + " " + file,
                         &output),
              0)
        << output << "\n" << text;
    EXPECT_EQ(output, "ok\n") << text;
  }

  static std::string Hex(const std::string& text) {
    static const char kDigits[] = "0123456789abcdef";
    std::string out;
    for (const unsigned char c : text) {
      out += kDigits[c >> 4];
      out += kDigits[c & 15];
    }
    return out;
  }

  testing::TempDir dir_;
  std::string calibration_;
};

// Run under sh: one call of the publisher with the expected arguments,
// nothing else run (no PWNED file, no "command not found").
TEST_F(ExportInjectionTest, TfCommandsRunOnlyThePublisher) {
  for (const auto& [format, expected] :
       {std::pair<std::string, std::string>{
            "tf_ros1",
            "tf2_ros\nstatic_transform_publisher\n0.120000000\n-0.340000000\n0.560000000\n"},
        {"tf_ros2", "run\ntf2_ros\nstatic_transform_publisher\n--x\n0.120000000\n"}}) {
    std::filesystem::remove(dir_.File("calls.txt"));
    const std::string text = Export(format);
    ASSERT_TRUE(WriteFileAtomically(dir_.File("tf.sh"), text).ok());
    std::string output;
    EXPECT_EQ(RunCommand("cd " + dir_.path() + " && PATH=" + dir_.File("bin") +
                             ":$PATH sh tf.sh",
                         &output),
              0)
        << output;
    EXPECT_EQ(output, "") << format;
    EXPECT_FALSE(testing::FileExists(dir_.File("PWNED"))) << format << "\n" << text;
    std::string calls;
    ASSERT_TRUE(ReadFileToString(dir_.File("calls.txt"), &calls).ok());
    EXPECT_EQ(calls.rfind(expected, 0), 0u) << format << "\n" << calls;
    EXPECT_EQ(calls.find("CALL_END"), calls.size() - 9) << format << "\n" << calls;
    EXPECT_THAT(calls, HasSubstr("imu_link\n")) << format;
    EXPECT_THAT(calls, HasSubstr("lidar_link\nCALL_END\n")) << format;
    // Every line that is not the command is a comment.
    ExpectPython(text, R"py(
import shlex
commands = [l for l in text.split('\n') if l and not l.startswith('#')]
assert len(commands) == 1, commands
words = shlex.split(commands[0], comments=True)
assert words[-2:] == ['imu_link', 'lidar_link'] or words[-4:] == [
    '--frame-id', 'imu_link', '--child-frame-id', 'lidar_link'], words
assert words[0] in ('rosrun', 'ros2'), words
)py");
  }
}

// The YAML formats load to exactly their keys; the source and reasons
// appear only in comment lines.
TEST_F(ExportInjectionTest, YamlHasOnlyItsKeys) {
  if (RunCommand(std::string(testing::kDebianPython) + " -c 'import yaml'") != 0) {
    GTEST_SKIP() << "no python3-yaml";
  }
  for (const auto& [format, keys] :
       {std::pair<std::string, std::string>{"fast_lio", "{'common': ['time_offset_lidar_to_imu'], "
                                                        "'mapping': ['extrinsic_est_en', "
                                                        "'extrinsic_T', 'extrinsic_R']}"},
        {"lio_sam", "{'lio_sam': ['extrinsicTrans', 'extrinsicRot', 'extrinsicRPY']}"},
        {"kalibr", "{'lidar0': ['frame_id', 'parent_frame_id', 'T_imu_lidar', 'T_lidar_imu', "
                   "'timeshift_lidar_imu', 'verdict']}"}}) {
    ExpectPython(Export(format), R"py(
import yaml
y = yaml.safe_load(text)
got = {k: list(v) for k, v in y.items()}
assert got == )py" + keys + R"py(, got
for line in text.split('\n'):
    if 'PWNED' in line or 'key' in line or 'more: 2' in line:
        assert line.startswith('#'), repr(line)
)py");
  }
  ExpectPython(Export("kalibr"), R"py(
import yaml
y = yaml.safe_load(text)['lidar0']
assert y['frame_id'] == 'lidar_link' and y['parent_frame_id'] == 'imu_link', y
)py");
}

// URDF: one <joint> with parent, child and origin; the comment holds the
// markup as text.
TEST_F(ExportInjectionTest, UrdfIsOneJoint) {
  ExpectPython(Export("urdf"), R"py(
joint = ET.fromstring(text)
assert joint.tag == 'joint' and [c.tag for c in joint] == ['parent', 'child', 'origin'], text
assert joint.find('parent').get('link') == 'imu_link'
assert joint.find('child').get('link') == 'lidar_link'
assert text.count('-->') == 1
assert text.index('-->') < text.index('<joint name="imu_link_to_lidar_link"')
)py");
}

// JSON: the source and the reasons exactly.
TEST_F(ExportInjectionTest, JsonKeepsTheStrings) {
  ExpectPython(Export("json"), R"py(
j = json.loads(text)
assert j['source'] == source, (j['source'], source)
assert j['verdict_reasons'] == reasons, j['verdict_reasons']
)py");
}

// Matrix: 13 lines of numbers, every other line a comment.
TEST_F(ExportInjectionTest, MatrixHasOnlyNumbersOutsideComments) {
  ExpectPython(Export("matrix"), R"py(
rows = [l for l in text.split('\n') if l and not l.startswith('#')]
assert len(rows) == 13, rows
for row in rows:
    [float(v) for v in row.split(' ')]
)py");
}

// Frame names are checked before they reach a format; names YAML would
// read as a number or null stay strings.
TEST_F(ExportInjectionTest, FrameNames) {
  ExportOptions options;
  options.format = "tf_ros1";
  options.allow_suspect = true;
  std::ostringstream out;
  for (const std::string& name : {std::string("\"><img src=x onerror=alert(1)>"),
                                  std::string("a\nb"), std::string("x; touch PWNED")}) {
    options.lidar_frame = name;
    EXPECT_FALSE(exporter::Run({calibration_, ""}, options, &out).ok()) << name;
  }
  EXPECT_EQ(out.str(), "");
  if (RunCommand(std::string(testing::kDebianPython) + " -c 'import yaml'") != 0) {
    GTEST_SKIP() << "no python3-yaml";
  }
  const std::string plain = dir_.File("plain.txtpb");
  ASSERT_TRUE(WriteFileAtomically(plain, "imu_from_lidar { rotation { w: 1 } }\n").ok());
  options.format = "kalibr";
  options.imu_frame = "null";
  options.lidar_frame = "1.0";
  ASSERT_TRUE(exporter::Run({plain, ""}, options, &out).ok());
  ExpectPython(out.str(), R"py(
import yaml
y = yaml.safe_load(text)['lidar0']
assert y['frame_id'] == '1.0' and y['parent_frame_id'] == 'null', y
)py");
}

// A NaN rotation is named as such.
TEST_F(ExportInjectionTest, NanRotationIsNamedNotFinite) {
  const std::string file = dir_.File("nan.txtpb");
  ASSERT_TRUE(WriteFileAtomically(file,
                                  "imu_from_lidar { rotation { w: nan x: 0 y: 0 z: 0 } "
                                  "translation { x: 0.1 } }\n")
                  .ok());
  ExportOptions options;
  options.format = "json";
  std::ostringstream out;
  const Status status = exporter::Run({file, ""}, options, &out);
  EXPECT_EQ(status.message(), file + ": imu_from_lidar.rotation is not finite (NaN or infinite)");
}

}  // namespace
}  // namespace tiltcal::exporter
