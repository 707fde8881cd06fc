#include "common/io/directory_lock.h"

#include <atomic>
#include <chrono>
#include <filesystem>
#include <sstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "tests/testing/test_env.h"

namespace tiltcal {
namespace {

// A second lock on a locked folder waits, says so, and is granted when the
// first is released.
TEST(DirectoryLock, SecondLockWaitsForTheFirst) {
  testing::TempDir tmp;
  const std::string dir = tmp.File("out");
  std::filesystem::create_directories(dir);
  auto first = std::make_unique<DirectoryLock>();
  ASSERT_TRUE(first->Acquire(dir, "first", nullptr).ok());

  std::atomic<bool> second_holds{false};
  std::ostringstream log;
  std::thread second_thread([&] {
    DirectoryLock second;
    EXPECT_TRUE(second.Acquire(dir, "tiltcal_decode", &log).ok());
    second_holds = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_FALSE(second_holds) << "the second lock did not wait";
  first.reset();
  second_thread.join();
  EXPECT_TRUE(second_holds);
  EXPECT_EQ(log.str(), "tiltcal_decode: waiting for another run writing into " + dir + "\n");
}

// The lock is the one flock(1) takes (Makefile.pipeline's lock on out/).
TEST(DirectoryLock, IsTheLockOfTheFlockCommand) {
  testing::TempDir tmp;
  const std::string dir = tmp.File("out");
  std::filesystem::create_directories(dir);
  const std::string try_lock = "flock -n '" + dir + "' true";
  {
    DirectoryLock lock;
    ASSERT_TRUE(lock.Acquire(dir, "test", nullptr).ok());
    EXPECT_NE(testing::RunCommand(try_lock), 0) << "flock(1) took a held lock";
  }
  EXPECT_EQ(testing::RunCommand(try_lock), 0) << "the lock was not released";
}

TEST(DirectoryLock, MissingFolderIsAnErrorNamingIt) {
  testing::TempDir tmp;
  DirectoryLock lock;
  const Status status = lock.Acquire(tmp.File("missing"), "test", nullptr);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(), tmp.File("missing") + ": cannot lock: No such file or directory");
}

// One spelling per folder: a process never waits for itself.
TEST(DirectoryLock, OutputDirectoryIsCanonical) {
  testing::TempDir tmp;
  const std::string dir = tmp.File("out");
  std::filesystem::create_directories(dir + "/sub");
  EXPECT_EQ(OutputDirectory(dir + "/sub/../imu.binpb"), OutputDirectory(dir + "/scans.binpb.lz4"));
  EXPECT_EQ(OutputDirectory("imu.binpb"), std::filesystem::current_path().string());
}

}  // namespace
}  // namespace tiltcal
