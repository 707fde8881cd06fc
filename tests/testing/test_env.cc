#include "tests/testing/test_env.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <array>
#include <filesystem>
#include <stdexcept>

namespace tiltcal::testing {

std::string SourceDir() { return TILTCAL_SOURCE_DIR; }
std::string BinaryDir() { return TILTCAL_BINARY_DIR; }
std::string ToolPath(const std::string& name) { return BinaryDir() + "/bin/" + name; }

std::string SharedFixturesDir() {
  const char* override_dir = std::getenv("TILTCAL_SHARED_FIXTURES");
  const std::string dir = override_dir != nullptr ? override_dir
                                                  : SourceDir() + "/../shared/fixtures";
  return std::filesystem::is_directory(dir) ? std::filesystem::canonical(dir).string() : "";
}

bool HaveRosbagPython() {
  static const bool have = RunCommand(std::string(kDebianPython) +
                                      " -c 'import rosbag, sensor_msgs.msg' 2>/dev/null") == 0;
  return have;
}

TempDir::TempDir() {
  std::string pattern = std::filesystem::temp_directory_path().string() + "/tiltcal_test_XXXXXX";
  if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  path_ = pattern;
}

TempDir::~TempDir() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

int RunCommand(const std::string& command, std::string* output) {
  const std::string full = command + " 2>&1";
  FILE* pipe = ::popen(full.c_str(), "r");
  if (pipe == nullptr) return -1;
  std::array<char, 4096> buffer;
  size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) {
    if (output != nullptr) output->append(buffer.data(), n);
  }
  const int status = ::pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool FileExists(const std::string& path) { return std::filesystem::exists(path); }

}  // namespace tiltcal::testing
