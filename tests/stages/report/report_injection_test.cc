// The report's outputs keep every string of their inputs as data: sequence
// folder names, the title and the string fields of the calibrations
// (verdict reasons, residual types, the dataset's sequence names, reasons
// and disagreements) carrying HTML, a javascript: URL, newlines, quotes and
// commas. The page is loaded in headless chromium; the CSV is read by
// Python's csv module and by stages/report/plot_extrinsics.py.
#include <filesystem>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/io/atomic_file.h"
#include "common/io/text_proto.h"
#include "stages/report/report.h"
#include "tests/stages/report/report_params_text.h"
#include "tests/testing/test_env.h"

namespace tiltcal::report {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr char kHtml[] = "\"><img src=x onerror=alert(1)>";
constexpr char kScript[] = "javascript:alert(1)";
// Lines, quotes, commas, a carriage return, an escape and U+2028.
constexpr char kLines[] =
    "one, \"two\"\r\ntouch PWNED\nextra_key: 1\x1b[31m\xe2\x80\xa8" "also_key: 2 --> <!-- end";

std::string Hex(const std::string& text) {
  static const char kDigits[] = "0123456789abcdef";
  std::string out;
  for (const unsigned char c : text) {
    out += kDigits[c >> 4];
    out += kDigits[c & 15];
  }
  return out;
}

proto::ResidualStatistics Residuals(const std::string& type) {
  proto::ResidualStatistics s;
  s.set_type(type);
  s.set_count(10);
  s.set_rms(1.0);
  s.set_histogram_min(-5);
  s.set_histogram_bin_width(1);
  for (int i = 0; i < 10; ++i) s.add_histogram_counts(i == 5 ? 10 : 0);
  s.set_time_start_s(0);
  s.set_time_bin_s(1);
  s.add_time_bin_count(10);
  s.add_time_bin_rms(1);
  s.add_time_bin_p05(-1);
  s.add_time_bin_median(0);
  s.add_time_bin_p95(1);
  return s;
}

proto::CalibrationResult Calibration(double x) {
  proto::CalibrationResult c;
  c.mutable_imu_from_lidar()->mutable_rotation()->set_w(1);
  c.mutable_imu_from_lidar()->mutable_translation()->set_x(x);
  c.set_time_offset_s(0.001);
  c.set_verdict(proto::CalibrationResult::WEAK);
  for (const char* text : {kHtml, kScript, kLines}) {
    c.add_verdict_reasons(text);
    *c.add_residual_statistics() = Residuals(text);
  }
  return c;
}

class ReportInjectionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    names_ = {kHtml, kScript, "run,1\n\"two\""};
    proto::CalibrationResult dataset = Calibration(0.1);
    for (size_t i = 0; i < names_.size(); ++i) {
      const std::string dir = dir_.File(names_[i]);
      std::filesystem::create_directories(dir);
      ASSERT_TRUE(WriteTextProto(dir + "/calibration.txtpb", Calibration(0.1 + 0.01 * i)).ok());
      paths_.sequence_dirs.push_back(dir);
      proto::DatasetSequence* s = dataset.add_sequences();
      s->set_name(names_[i]);
      s->set_used(true);
      s->set_reason(kLines);
      s->set_disagreement(kHtml);
      *dataset.add_sequences() = *s;
      dataset.mutable_sequences()->rbegin()->clear_reason();
    }
    ASSERT_TRUE(WriteTextProto(dir_.File("calibration.txtpb"), dataset).ok());
    paths_.dataset_calibration = dir_.File("calibration.txtpb");
    paths_.out = dir_.File("repeatability.txt");
    paths_.out_csv = dir_.File("repeatability.csv");
    paths_.out_html = dir_.File("report.html");
    paths_.title = std::string(kHtml) + "\n" + kScript;
    const Status status = report::Run(paths_, DefaultReportParams(), nullptr);
    ASSERT_TRUE(status.ok()) << status.message();
    ASSERT_TRUE(ReadFileToString(paths_.out_html, &html_).ok());
  }

  std::string ReadLog() const {
    std::string log;
    EXPECT_TRUE(ReadFileToString(dir_.File("chromium.log"), &log).ok());
    return log;
  }

  testing::TempDir dir_;
  std::vector<std::string> names_;
  ReportPaths paths_;
  std::string html_;
};

// Every row has the header's 14 columns and its name intact.
TEST_F(ReportInjectionTest, CsvKeepsColumnsAndNames) {
  const std::string script = dir_.File("read_csv.py");
  ASSERT_TRUE(WriteFileAtomically(script,
                                  "import csv, sys\n"
                                  "with open(sys.argv[1], newline='') as f:\n"
                                  "    for row in csv.reader(f):\n"
                                  "        print(len(row), row[0].encode().hex())\n")
                  .ok());
  std::string output;
  ASSERT_EQ(testing::RunCommand(std::string(testing::kDebianPython) + " " + script + " " +
                                    paths_.out_csv,
                                &output),
            0)
      << output;
  std::string expected = "14 " + Hex("sequence") + "\n";
  for (const std::string& name : names_) expected += "14 " + Hex(name) + "\n";
  expected += "14 " + Hex("mean") + "\n14 " + Hex("sigma") + "\n";
  EXPECT_EQ(output, expected);
  // The plots read the same file.
  if (testing::RunCommand(std::string(testing::kDebianPython) + " -c 'import matplotlib'") != 0) {
    GTEST_SKIP() << testing::kDebianPython << " has no matplotlib (python3-matplotlib)";
  }
  ASSERT_EQ(testing::RunCommand(std::string(testing::kDebianPython) + " " +
                                    testing::SourceDir() + "/stages/report/plot_extrinsics.py --csv=" +
                                    paths_.out_csv + " --out_dir=" + dir_.path(),
                                &output),
            0)
      << output;
  EXPECT_TRUE(testing::FileExists(dir_.File("extrinsic_positions.png")));
}

// The page in chromium: no element, attribute or handler of the payloads
// (only the page's own elements), no alert, every link a file next to the
// page: the three calibrations and the dataset's, whatever their folders
// are called.
TEST_F(ReportInjectionTest, ChromiumShowsThePayloadsAsText) {
  if (testing::RunCommand("command -v chromium > /dev/null") != 0) {
    GTEST_SKIP() << "chromium is not installed (scripts/setup.sh installs it)";
  }
  std::string expected_targets;
  for (const std::string& name : names_) {
    expected_targets += "'" + Hex(dir_.File(name) + "/calibration.txtpb") + "',";
  }
  expected_targets += "'" + Hex(paths_.dataset_calibration) + "'";
  std::string checked = html_;
  const size_t head = checked.find("<head>");
  ASSERT_NE(head, std::string::npos);
  checked.insert(head + 6, "<script>window.alerts = 0; window.alert = () => ++window.alerts;"
                           "</script>");
  checked +=
      "<script>window.addEventListener('load', () => {"
      "const allowed = new Set(['html', 'head', 'meta', 'title', 'style', 'script', 'body', "
      "'h1', 'h2', 'h3', 'h4', 'p', 'table', 'tbody', 'tr', 'th', 'td', 'ul', 'li', 'a', "
      "'section', 'span', 'div', 'figure', 'figcaption', 'img', 'details', 'summary', 'pre', "
      "'code', 'br', 'svg', 'title', 'rect', 'polyline', 'polygon', 'line', 'text']);"
      "const all = [...document.querySelectorAll('*')];"
      "const hex = s => [...new TextEncoder().encode(s)].map(x => x.toString(16)"
      ".padStart(2, '0')).join('');"
      "const targets = new Set([" + expected_targets + "]);"
      "const anchors = [...document.querySelectorAll('a')];"
      "const b = document.body.dataset;"
      "b.foreign = all.map(e => e.localName).filter(n => !allowed.has(n)).join(' ') || 'none';"
      "b.handlers = all.filter(e => [...e.attributes].some(a => a.name.startsWith('on'))).length;"
      "b.images = document.images.length;"
      "b.scripts = document.scripts.length;"
      "b.anchors = anchors.length;"
      "b.scriptlinks = document.querySelectorAll('a[href^=\"javascript\" i]').length;"
      "b.nonfilelinks = anchors.filter(a => a.protocol !== 'file:').length;"
      "b.linkedfiles = anchors.filter(a => targets.has(hex(decodeURIComponent(a.pathname))))"
      ".length;"
      "setTimeout(() => { b.alerts = window.alerts; b.done = 1; }, 500);"
      "});</script>\n";
  const std::string page = dir_.File("report_checked.html");
  ASSERT_TRUE(WriteFileAtomically(page, checked).ok());
  std::string dom;
  ASSERT_EQ(testing::RunCommand("chromium --headless --no-sandbox --disable-gpu --no-first-run "
                                "--user-data-dir=" + dir_.File("profile") +
                                    " --enable-logging=stderr --v=0 --virtual-time-budget=3000 "
                                    "--dump-dom file://" + page +
                                    " 2> " + dir_.File("chromium.log"),
                                &dom),
            0)
      << dom;
  EXPECT_THAT(dom, HasSubstr("data-foreign=\"none\" data-handlers=\"0\" data-images=\"0\" "
                             "data-scripts=\"2\" data-anchors=\"4\" data-scriptlinks=\"0\" "
                             "data-nonfilelinks=\"0\" data-linkedfiles=\"4\" data-alerts=\"0\" "
                             "data-done=\"1\""))
      << dom.substr(dom.find("<body"), 600) << ReadLog();
  // Shown as text where they belong.
  EXPECT_THAT(dom, HasSubstr("<li>\"&gt;&lt;img src=x onerror=alert(1)&gt;</li>"));
  EXPECT_THAT(dom, Not(HasSubstr("<img src")));
}

}  // namespace
}  // namespace tiltcal::report
