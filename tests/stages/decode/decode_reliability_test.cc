// tiltcal_decode on stamps no sequence can have, on output paths that cannot
// be written, and killed while it writes: one error line naming the bag and
// the message or field, exit 1, no output; a kill leaves the old pair of
// outputs or the new one, never one of each.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/io/atomic_file.h"
#include "common/io/record_stream.h"
#include "tests/bag/ros1/bag_test_util.h"
#include "tests/stages/decode/vehicle_bag.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/imu.pb.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal {
namespace {

namespace fs = std::filesystem;

class DecodeReliability : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(testing::FileExists(testing::ToolPath("tiltcal_decode")))
        << "build the tiltcal_decode target first";
    fs::create_directories(tmp_.File("out"));
  }

  std::string VehicleBag(const std::string& name, const testing::VehicleBagOptions& options) {
    const std::string bag = tmp_.File(name);
    EXPECT_TRUE(testing::WriteVehicleBag(bag, options));
    return bag;
  }

  std::string DecodeCommand(const std::string& bag, const std::string& extra = "") {
    return testing::ToolPath("tiltcal_decode") + " --bag='" + bag + "' --out_imu=" + Imu() +
           " --out_scans=" + Scans() + " " + extra;
  }
  std::string Imu() const { return tmp_.File("out/imu.binpb"); }
  std::string Scans() const { return tmp_.File("out/scans.binpb.lz4"); }

  // Exit 1, one line naming every string of `must_contain`, nothing in out/.
  void ExpectCleanFailure(int rc, const std::string& output,
                          const std::vector<std::string>& must_contain) {
    EXPECT_EQ(rc, 1) << output;
    EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;
    for (const std::string& s : must_contain) {
      EXPECT_NE(output.find(s), std::string::npos) << "'" << s << "' not in: " << output;
    }
    EXPECT_TRUE(fs::is_empty(tmp_.File("out"))) << "output left behind";
  }

  testing::TempDir tmp_;
};

TEST_F(DecodeReliability, ImuStampFarInTheFutureIsRefused) {
  testing::VehicleBagOptions options;
  options.far_future_imu_index = 150;
  const std::string bag = VehicleBag("far.bag", options);
  std::string output;
  const int rc = testing::RunCommand(DecodeCommand(bag), &output);
  ExpectCleanFailure(rc, output,
                     {bag, "IMU stamps jump by", "to 4294967295.000000000 s", "max_stamp_gap_s = 60"});
}

TEST_F(DecodeReliability, ScanStampJumpIsRefusedNamingTheMessage) {
  testing::VehicleBagOptions options;
  const std::string bag = VehicleBag("vehicle.bag", options);
  const std::string params = tmp_.File("params.txtpb");
  std::string text =
      testing::ReadFileOrEmpty(testing::SourceDir() + "/stages/decode/default_params.txtpb");
  const std::string line = "max_stamp_gap_s: 60";
  ASSERT_NE(text.find(line), std::string::npos);
  text.replace(text.find(line), line.size(), "max_stamp_gap_s: 0.05");
  std::ofstream(params) << text;
  std::string output;
  const int rc = testing::RunCommand(DecodeCommand(bag, "--params=" + params), &output);
  // The IMU (200 Hz) passes; the scans (10 Hz) step by 0.1 s.
  ExpectCleanFailure(rc, output, {bag, "topic '/points' message 1", "max_stamp_gap_s = 0.05"});
}

TEST_F(DecodeReliability, ZeroStampsAreRefused) {
  testing::VehicleBagOptions options;
  options.zero_stamps = true;
  const std::string bag = VehicleBag("zero.bag", options);
  std::string output;
  const int rc = testing::RunCommand(DecodeCommand(bag), &output);
  ExpectCleanFailure(rc, output, {bag, "message 0", "header stamp is 0"});
}

TEST_F(DecodeReliability, HugeStartOffsetIsAParamsError) {
  const std::string bag = VehicleBag("vehicle.bag", {});
  const std::string params = tmp_.File("params.txtpb");
  std::string text =
      testing::ReadFileOrEmpty(testing::SourceDir() + "/stages/decode/default_params.txtpb");
  const std::string line = "start_offset_s: 0";
  ASSERT_NE(text.find(line), std::string::npos);
  text.replace(text.find(line), line.size(), "start_offset_s: 1e300");
  std::ofstream(params) << text;
  std::string output;
  const int rc = testing::RunCommand(DecodeCommand(bag, "--params=" + params), &output);
  ExpectCleanFailure(rc, output, {params, "start_offset_s", "maximum"});
}

TEST_F(DecodeReliability, MissingOutputDirectoryIsAnErrorBeforeReading) {
  // The bag does not even exist: the output path is checked first.
  std::string output;
  const std::string missing_dir = tmp_.File("no/such/dir");
  const int rc = testing::RunCommand(testing::ToolPath("tiltcal_decode") + " --bag=" +
                                         tmp_.File("absent.bag") + " --out_imu=" + missing_dir +
                                         "/imu.binpb --out_scans=" + Scans(),
                                     &output);
  ExpectCleanFailure(rc, output, {missing_dir + "/imu.binpb", "does not exist"});
}

TEST_F(DecodeReliability, StaleTemporariesOfDeadRunsAreRemoved) {
  const std::string bag = VehicleBag("vehicle.bag", {});
  // No process has a pid above pid_max (at most 2^22 on Linux).
  const std::string stale = Imu() + ".tmp.999999999";
  std::ofstream(stale) << "partial";
  const std::string alive = Scans() + ".tmp.1";  // pid 1 always runs: kept
  std::ofstream(alive) << "partial";
  std::string output;
  ASSERT_EQ(testing::RunCommand(DecodeCommand(bag), &output), 0) << output;
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(alive));
  fs::remove(alive);
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(tmp_.File("out"))) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"imu.binpb", "scans.binpb.lz4"}));
}

// The bag a stream was decoded from (its provenance), "" when unreadable.
template <typename Record>
std::string SourceBag(const std::string& path, std::string* error) {
  RecordReader reader;
  const Status status = reader.Open(path, Record::descriptor()->full_name());
  if (!status.ok()) {
    *error = status.message();
    return "";
  }
  for (const proto::InputFile& input : reader.header().provenance().inputs()) {
    if (input.role() == "bag") return input.path();
  }
  return "";
}

TEST_F(DecodeReliability, AKillAtAnyMomentLeavesTheOldPairOrTheNewOne) {
  testing::VehicleBagOptions old_options;
  old_options.duration_s = 6;
  const std::string old_bag = VehicleBag("old.bag", old_options);
  testing::VehicleBagOptions new_options;
  new_options.duration_s = 60;
  const std::string new_bag = VehicleBag("new.bag", new_options);
  std::string output;
  // How long a whole run of the new bag takes, to spread the kills over it.
  const auto start = std::chrono::steady_clock::now();
  ASSERT_EQ(testing::RunCommand(DecodeCommand(new_bag), &output), 0) << output;
  const auto run_us = std::chrono::duration_cast<std::chrono::microseconds>(
                          std::chrono::steady_clock::now() - start)
                          .count();
  std::mt19937 random(7);
  int old_pairs = 0, new_pairs = 0, interrupted_commits = 0;
  for (int trial = 0; trial < 10; ++trial) {
    ASSERT_EQ(testing::RunCommand(DecodeCommand(old_bag), &output), 0) << output;
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      const std::string command = DecodeCommand(new_bag) + " 2>/dev/null";
      ::execl("/bin/sh", "sh", "-c", ("exec " + command).c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    // Kills from the start to the end of a whole run.
    const auto delay_us = std::uniform_int_distribution<long>(0, run_us)(random);
    ::usleep(static_cast<useconds_t>(delay_us));
    ::kill(pid, SIGKILL);
    int wstatus = 0;
    ::waitpid(pid, &wstatus, 0);
    if (fs::exists(CommitManifestPath(Imu())) || fs::exists(CommitManifestPath(Scans()))) {
      // Killed inside the commit: readers refuse both files until the next
      // run completes the commit.
      ++interrupted_commits;
      std::string error;
      EXPECT_EQ(SourceBag<proto::ImuSample>(Imu(), &error), "");
      ASSERT_TRUE(CompleteInterruptedCommit(Imu()).ok());
      ASSERT_TRUE(CompleteInterruptedCommit(Scans()).ok());
    }
    std::string error;
    const std::string imu_source = SourceBag<proto::ImuSample>(Imu(), &error);
    const std::string scans_source = SourceBag<proto::Scan>(Scans(), &error);
    ASSERT_FALSE(imu_source.empty()) << error;
    EXPECT_EQ(imu_source, scans_source) << "trial " << trial << ", killed after " << delay_us
                                        << " us";
    ++(imu_source == new_bag ? new_pairs : old_pairs);
  }
  // The next run starts clean: the killed runs' temporaries are gone.
  ASSERT_EQ(testing::RunCommand(DecodeCommand(old_bag), &output), 0) << output;
  for (const auto& entry : fs::directory_iterator(tmp_.File("out"))) {
    const std::string name = entry.path().filename().string();
    EXPECT_TRUE(name == "imu.binpb" || name == "scans.binpb.lz4") << name << " left behind";
  }
  std::cout << "kills: " << old_pairs << " old pairs, " << new_pairs << " new pairs, "
            << interrupted_commits << " interrupted commits completed\n";
}

}  // namespace
}  // namespace tiltcal
