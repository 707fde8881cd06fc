#include "common/io/direct_file_output.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/io/atomic_file.h"
#include "common/io/record_stream.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal {
namespace {

// `size` bytes of a pattern that repeats every 251 bytes (never at a block
// boundary), so a misplaced block shows.
std::string Pattern(size_t size) {
  std::string bytes(size, '\0');
  for (size_t i = 0; i < size; ++i) bytes[i] = static_cast<char>(i * 131 % 251);
  return bytes;
}

std::string ReadAll(const std::string& path) {
  std::string contents;
  EXPECT_TRUE(ReadFileToString(path, &contents).ok());
  return contents;
}

// Writes `contents` in pieces of the given sizes (cycled) and closes.
void WriteInPieces(DirectFileOutput* output, const std::string& contents,
                   const std::vector<size_t>& piece_sizes) {
  size_t at = 0;
  for (size_t i = 0; at < contents.size(); ++i) {
    const size_t piece = std::min(piece_sizes[i % piece_sizes.size()], contents.size() - at);
    ASSERT_TRUE(output->Write(contents.data() + at, piece));
    at += piece;
  }
  ASSERT_TRUE(output->Close());
}

TEST(DirectFileOutput, TheFileHasExactlyTheBytesWrittenWhateverTheSizes) {
  testing::TempDir dir;
  const std::vector<size_t> sizes = {0,
                                     1,
                                     kDirectWriteAlignment - 1,
                                     kDirectWriteAlignment,
                                     kDirectWriteAlignment + 1,
                                     kDirectWriteBufferBytes,
                                     kDirectWriteBufferBytes + 7,
                                     // more than all buffers: they are reused
                                     (kDirectWriteBuffers + 2) * kDirectWriteBufferBytes + 4093};
  for (const size_t size : sizes) {
    SCOPED_TRACE(size);
    const std::string contents = Pattern(size);
    for (const std::vector<size_t>& pieces :
         {std::vector<size_t>{size + 1}, std::vector<size_t>{4, 262144, 13}}) {
      const std::string path = dir.File("out.bin");
      DirectFileOutput output;
      ASSERT_TRUE(output.Open(path));
      WriteInPieces(&output, contents, pieces);
      EXPECT_TRUE(ReadAll(path) == contents);
    }
  }
}

TEST(DirectFileOutput, OpenTruncatesAnExistingFile) {
  testing::TempDir dir;
  const std::string path = dir.File("out.bin");
  ASSERT_TRUE(WriteFileAtomically(path, Pattern(3 * kDirectWriteBufferBytes)).ok());
  DirectFileOutput output;
  ASSERT_TRUE(output.Open(path));
  WriteInPieces(&output, "short", {5});
  EXPECT_EQ(ReadAll(path), "short");
}

TEST(DirectFileOutput, WritesPastThePageCacheOnAnOrdinaryFileSystem) {
  testing::TempDir dir;
  DirectFileOutput output;
  ASSERT_TRUE(output.Open(dir.File("out.bin")));
  // ext4, xfs and btrfs accept O_DIRECT; a test directory on tmpfs does not.
  if (!output.direct()) GTEST_SKIP() << dir.path() << " does not accept O_DIRECT";
  const std::string contents = Pattern(2 * kDirectWriteBufferBytes + 100);
  ASSERT_TRUE(output.Write(contents.data(), contents.size()));
  ASSERT_TRUE(output.Close());
  EXPECT_FALSE(output.direct());  // the partial last block went through the page cache
  EXPECT_TRUE(ReadAll(dir.File("out.bin")) == contents);
}

// The path a file system without O_DIRECT takes.
TEST(DirectFileOutput, ThroughThePageCacheTheSameBytes) {
  testing::TempDir dir;
  DirectFileOutput output;
  ASSERT_TRUE(output.Open(dir.File("out.bin"), /*direct=*/false));
  EXPECT_FALSE(output.direct());
  const std::string contents = Pattern(2 * kDirectWriteBufferBytes + 12345);
  WriteInPieces(&output, contents, {1000});
  EXPECT_TRUE(ReadAll(dir.File("out.bin")) == contents);
}

// tmpfs refuses O_DIRECT before Linux 6.6 and accepts it since: either way
// the same bytes.
TEST(DirectFileOutput, OnTmpfsTheSameBytes) {
  const std::filesystem::path shm = "/dev/shm";
  if (!std::filesystem::is_directory(shm)) GTEST_SKIP() << "no /dev/shm (tmpfs) here";
  const std::string path = (shm / ("tiltcal_direct_test." + std::to_string(::getpid()))).string();
  DirectFileOutput output;
  ASSERT_TRUE(output.Open(path));
  const std::string contents = Pattern(kDirectWriteBufferBytes + 12345);
  WriteInPieces(&output, contents, {1000});
  EXPECT_TRUE(ReadAll(path) == contents);
  std::filesystem::remove(path);
}

TEST(DirectFileOutput, AFailedWriteIsReportedWithItsErrno) {
  // /dev/full refuses every write with ENOSPC.
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
  DirectFileOutput output;
  ASSERT_TRUE(output.Open("/dev/full"));
  const std::string contents = Pattern(kDirectWriteBufferBytes / 2);
  ASSERT_TRUE(output.Write(contents.data(), contents.size()));
  errno = 0;
  EXPECT_FALSE(output.Close());
  EXPECT_EQ(errno, ENOSPC);
}

TEST(DirectFileOutput, AFailedWriteStopsLaterWrites) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
  DirectFileOutput output;
  ASSERT_TRUE(output.Open("/dev/full"));
  const std::string buffer = Pattern(kDirectWriteBufferBytes);
  bool failed = false;
  // Every full buffer is written in the background; once one has failed,
  // Write() says so when it needs a free buffer.
  for (size_t i = 0; i < 10 * kDirectWriteBuffers && !failed; ++i) {
    failed = !output.Write(buffer.data(), buffer.size());
  }
  EXPECT_TRUE(failed);
  EXPECT_EQ(errno, ENOSPC);
  EXPECT_FALSE(output.Close());
}

TEST(DirectFileOutput, OpeningInAMissingDirectoryFails) {
  testing::TempDir dir;
  DirectFileOutput output;
  errno = 0;
  EXPECT_FALSE(output.Open(dir.File("missing/out.bin")));
  EXPECT_EQ(errno, ENOENT);
}

TEST(DirectFileOutput, AbandonLeavesNothingRunning) {
  testing::TempDir dir;
  DirectFileOutput output;
  ASSERT_TRUE(output.Open(dir.File("out.bin")));
  const std::string contents = Pattern(2 * kDirectWriteBufferBytes + 1);
  ASSERT_TRUE(output.Write(contents.data(), contents.size()));
  output.Abandon();
  // Reusable after Abandon.
  ASSERT_TRUE(output.Open(dir.File("again.bin")));
  WriteInPieces(&output, contents, {65536});
  EXPECT_TRUE(ReadAll(dir.File("again.bin")) == contents);
}

// A record stream written past the page cache is the same file as one
// written through it.
TEST(DirectFileOutput, ARecordStreamPastThePageCacheIsTheSameFile) {
  testing::TempDir dir;
  proto::Provenance provenance;
  provenance.set_producer("direct_file_output_test");
  proto::Scan scan;
  for (int i = 0; i < 200000; ++i) {
    scan.add_x(0.001f * static_cast<float>(i));
    scan.add_y(-0.5f * static_cast<float>(i % 97));
    scan.add_z(1.0f);
  }
  Lz4FrameOptions stored;
  stored.compress_blocks = false;
  std::vector<std::string> files;
  for (const bool bypass : {false, true}) {
    AtomicFileOptions file_options;
    file_options.bypass_page_cache = bypass;
    const std::string path = dir.File(bypass ? "direct.binpb.lz4" : "cached.binpb.lz4");
    RecordWriter writer;
    ASSERT_TRUE(writer.Open(path, proto::Scan::descriptor()->full_name(), provenance, stored,
                            file_options)
                    .ok());
    for (int i = 0; i < 7; ++i) {
      scan.set_stamp_ns(i);
      ASSERT_TRUE(writer.Write(scan).ok());
    }
    ASSERT_TRUE(writer.Close().ok());
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}),
              static_cast<long>(files.size() + 1));  // no temporary left
    files.push_back(ReadAll(path));
  }
  EXPECT_GT(files[0].size(), 7 * 200000 * 12);
  EXPECT_TRUE(files[0] == files[1]);
}

TEST(DirectFileOutput, AnAbandonedAtomicFileLeavesNothing) {
  testing::TempDir dir;
  {
    AtomicFile file;
    AtomicFileOptions options;
    options.bypass_page_cache = true;
    ASSERT_TRUE(file.Open(dir.File("out.bin"), options).ok());
    const std::string contents = Pattern(kDirectWriteBufferBytes + 1);
    ASSERT_EQ(std::fwrite(contents.data(), 1, contents.size(), file.file()), contents.size());
  }
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 0);
}

}  // namespace
}  // namespace tiltcal
