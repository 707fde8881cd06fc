#ifndef TILTCAL_TESTS_BAG_ROS1_BAG_TEST_UTIL_H_
#define TILTCAL_TESTS_BAG_ROS1_BAG_TEST_UTIL_H_

// Helpers of the tests that read ROS1 bags (tests/bag/ros1, the decode
// stage): bags written and oracle output dumped by Debian's python rosbag
// (tests/oracle/), cached in the build tree (keyed by the script's contents)
// so that each test process does not rerun python.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "tests/testing/test_env.h"

namespace tiltcal::testing {

inline std::string ReadFileOrEmpty(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline std::vector<std::string> SplitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

inline std::vector<std::string> SplitWords(const std::string& line) {
  std::vector<std::string> words;
  std::istringstream in(line);
  std::string word;
  while (in >> word) words.push_back(word);
  return words;
}

// Runs `make(dir)` once into BinaryDir()/test_data/<name>_<key hash> and
// returns that directory ("" on failure, *log says why). Safe when several
// test processes race: each builds in its own temporary directory and renames.
inline std::string CachedDir(const std::string& name, const std::string& key,
                             const std::function<bool(const std::string&, std::string*)>& make,
                             std::string* log) {
  namespace fs = std::filesystem;
  const std::string root = BinaryDir() + "/test_data";
  const std::string dir =
      root + "/" + name + "_" + std::to_string(std::hash<std::string>()(key));
  if (fs::is_directory(dir)) return dir;
  std::error_code ec;
  fs::create_directories(root, ec);
  const std::string temp = dir + ".tmp" + std::to_string(::getpid());
  fs::remove_all(temp, ec);
  fs::create_directories(temp, ec);
  if (!make(temp, log)) {
    fs::remove_all(temp, ec);
    return "";
  }
  fs::rename(temp, dir, ec);
  if (ec) fs::remove_all(temp, ec);  // another process won the race
  return fs::is_directory(dir) ? dir : "";
}

// Bags written by tests/oracle/write_test_bags.py with the real rosbag library
// ("" when that fails or python3-rosbag is missing; callers then check
// HaveRosbagPython() to skip). Python only runs when the cache is missing.
inline std::string WrittenBagsDir(std::string* log) {
  const std::string script = SourceDir() + "/tests/oracle/write_test_bags.py";
  return CachedDir("decode_bags", ReadFileOrEmpty(script),
                   [&](const std::string& dir, std::string* out) {
                     if (!HaveRosbagPython()) return false;
                     return RunCommand(std::string(kDebianPython) + " " + script + " " + dir,
                                       out) == 0;
                   },
                   log);
}

// Lines of tests/oracle/rosbag_dump.py for `topic` of `bag` (empty when
// python3-rosbag is missing).
inline std::vector<std::string> OracleDump(const std::string& bag, const std::string& topic,
                                           std::string* log) {
  const std::string script = SourceDir() + "/tests/oracle/rosbag_dump.py";
  const std::string dir = CachedDir(
      "rosbag_dump", ReadFileOrEmpty(script) + "\n" + bag + "\n" + topic,
      [&](const std::string& d, std::string* out) {
        if (!HaveRosbagPython()) return false;
        // The braces keep python's stderr out of the dump (RunCommand adds 2>&1).
        return RunCommand("{ " + std::string(kDebianPython) + " " + script + " '" + bag +
                              "' '" + topic + "' > " + d + "/dump.txt; }",
                          out) == 0;
      },
      log);
  if (dir.empty()) return {};
  return SplitLines(ReadFileOrEmpty(dir + "/dump.txt"));
}

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_BAG_ROS1_BAG_TEST_UTIL_H_
