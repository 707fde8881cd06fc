#include "common/io/atomic_file.h"

#include <algorithm>
#include <filesystem>
#include <vector>

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

TEST(AtomicFile, WriteBehindStartsEveryCompleteWindowAndKeepsTheContents) {
  testing::TempDir dir;
  const std::string path = dir.File("out.bin");
  // Three and a half windows of a byte pattern, written in odd-sized pieces.
  std::string contents(static_cast<size_t>(kWriteBehindBytes) * 7 / 2, '\0');
  for (size_t i = 0; i < contents.size(); ++i) contents[i] = static_cast<char>(i * 131 % 251);
  AtomicFile file;
  ASSERT_TRUE(file.Open(path).ok());
  std::vector<long long> started;
  constexpr size_t kPiece = 3'000'001;
  for (size_t begin = 0; begin < contents.size(); begin += kPiece) {
    const size_t size = std::min(kPiece, contents.size() - begin);
    ASSERT_EQ(std::fwrite(contents.data() + begin, 1, size, file.file()), size);
    file.WriteBehind();
    started.push_back(file.write_behind_bytes());
  }
  // Never past what reached the kernel (the FILE buffer may hold a tail),
  // whole windows only, and every complete window once it is written.
  for (size_t i = 0; i < started.size(); ++i) {
    const long long written = static_cast<long long>(std::min(contents.size(), (i + 1) * kPiece));
    EXPECT_LE(started[i], written);
    EXPECT_EQ(started[i] % kWriteBehindBytes, 0);
    EXPECT_GE(started[i], written - 2 * kWriteBehindBytes) << "piece " << i;
  }
  EXPECT_EQ(started.back(), 3 * kWriteBehindBytes);
  ASSERT_TRUE(file.Commit().ok());
  std::string read_back;
  ASSERT_TRUE(ReadFileToString(path, &read_back).ok());
  EXPECT_TRUE(read_back == contents);
}

TEST(AtomicFile, UnwritableDirectoryIsAClearError) {
  AtomicFile file;
  const Status status = file.Open("/nonexistent_dir/out.txt");
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("/nonexistent_dir/out.txt"), std::string::npos);
}

}  // namespace
}  // namespace tiltcal
