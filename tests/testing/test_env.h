#ifndef TILTCAL_TESTS_TESTING_TEST_ENV_H_
#define TILTCAL_TESTS_TESTING_TEST_ENV_H_

#include <string>

namespace tiltcal::testing {

// The project's source and build directories.
std::string SourceDir();
std::string BinaryDir();
// build/bin/<name>
std::string ToolPath(const std::string& name);

// `../shared/fixtures` next to the source tree, or "" when it is absent.
// Tests that need it call GTEST_SKIP() with a message when it is empty.
std::string SharedFixturesDir();

// Debian's interpreter with python3-rosbag (never the `python3` on PATH).
inline constexpr char kDebianPython[] = "/usr/bin/python3";
// True when /usr/bin/python3 can import rosbag and sensor_msgs.
bool HaveRosbagPython();

// A fresh directory removed (recursively) on destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }
  std::string File(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

// Runs `command` with /bin/sh; returns its exit status (-1 if it did not
// exit normally). stdout and stderr go to *output when given.
int RunCommand(const std::string& command, std::string* output = nullptr);

bool FileExists(const std::string& path);

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_TESTING_TEST_ENV_H_
