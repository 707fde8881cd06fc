#include "common/io/atomic_file.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "tests/testing/test_env.h"

namespace tiltcal {
namespace {

TEST(AtomicFile, NothingAtThePathBeforeCommit) {
  testing::TempDir dir;
  const std::string path = dir.File("out.txt");
  AtomicFile file;
  ASSERT_TRUE(file.Open(path).ok());
  std::fputs("hello", file.file());
  EXPECT_FALSE(testing::FileExists(path));
  ASSERT_TRUE(file.Commit().ok());
  std::string contents;
  ASSERT_TRUE(ReadFileToString(path, &contents).ok());
  EXPECT_EQ(contents, "hello");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(AtomicFile, AbandonKeepsThePreviousVersion) {
  testing::TempDir dir;
  const std::string path = dir.File("out.txt");
  ASSERT_TRUE(WriteFileAtomically(path, "old").ok());
  {
    AtomicFile file;
    ASSERT_TRUE(file.Open(path).ok());
    std::fputs("new, never committed", file.file());
  }
  std::string contents;
  ASSERT_TRUE(ReadFileToString(path, &contents).ok());
  EXPECT_EQ(contents, "old");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(AtomicFile, UnwritableDirectoryIsAClearError) {
  AtomicFile file;
  const Status status = file.Open("/nonexistent_dir/out.txt");
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("/nonexistent_dir/out.txt"), std::string::npos);
}

}  // namespace
}  // namespace tiltcal
