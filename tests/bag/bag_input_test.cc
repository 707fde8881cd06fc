// OpenBagInput on the shapes an input can have, held to "nothing skipped
// without a word": entries of a folder named like bags that cannot be read
// (dangling links, link loops, FIFOs), FIFOs given as the bag, and a rosbag2
// MCAP folder whose metadata.yaml is read as strictly as the sqlite3 one
// (quoted values, compression_format, files it does not list).
#include "bag/input/bag_input.h"

#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/bag/ros2/ros2_oracle.h"
#include "tests/testing/test_env.h"

namespace tiltcal::bag {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

#define SKIP_WITHOUT_ORACLE()                                   \
  if (const std::string missing = testing::Ros2OracleMissing(); \
      !missing.empty()) {                                       \
    GTEST_SKIP() << missing;                                    \
  }

Status Open(const std::string& path, std::unique_ptr<MessageReader>* reader) {
  return OpenBagInput(path, Ros1ChunkSettings(), reader);
}

std::string Joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& line : lines) out += line + "\n";
  return out;
}

// A folder of one good MCAP and one entry named like a bag that is not a
// file: an error naming the entry, never a silent skip.
TEST(BagInput, FolderEntriesNamedLikeBagsThatCannotBeReadAreErrors) {
  SKIP_WITHOUT_ORACLE();
  struct Case {
    const char* name;
    const char* says;
  };
  for (const Case& c : {Case{"dangling.mcap", "a symbolic link to"},
                        Case{"loop.bag", "a symbolic link loop"},
                        Case{"pipe.db3", "a FIFO (named pipe), not a regular file"}}) {
    TempDir dir;
    const std::string folder = dir.File("run");
    fs::create_directory(folder);
    std::string error;
    ASSERT_TRUE(testing::WriteRos2Bag(folder + "/a.mcap", "--format=mcap", "", &error)) << error;
    const std::string entry = folder + "/" + c.name;
    if (std::string(c.name) == "dangling.mcap") {
      fs::create_symlink(folder + "/gone.mcap", entry);
    } else if (std::string(c.name) == "loop.bag") {
      fs::create_symlink(entry, entry);
    } else {
      ASSERT_EQ(::mkfifo(entry.c_str(), 0600), 0);
    }
    std::unique_ptr<MessageReader> reader;
    const auto start = std::chrono::steady_clock::now();
    const Status status = Open(folder, &reader);
    ASSERT_FALSE(status.ok()) << c.name;
    EXPECT_NE(status.message().find(entry + ": "), std::string::npos) << status.message();
    EXPECT_NE(status.message().find(c.says), std::string::npos) << status.message();
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
              1.0);
  }
}

// A sub-folder named like a bag is not read, as documented.
TEST(BagInput, SubFoldersOfAFolderOfBagsAreNotRead) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  const std::string folder = dir.File("run");
  fs::create_directories(folder + "/old.bag");
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(folder + "/a.mcap", "--format=mcap", "", &error)) << error;
  std::unique_ptr<MessageReader> reader;
  const Status status = Open(folder, &reader);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(reader->TotalMessageCount(), 54);
}

TEST(BagInput, AFifoAsTheBagIsRefusedAtOnce) {
  TempDir dir;
  const std::string fifo = dir.File("bag.mcap");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::unique_ptr<MessageReader> reader;
  const auto start = std::chrono::steady_clock::now();
  const Status status = Open(fifo, &reader);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(),
            fifo + ": a FIFO (named pipe), not a regular file; inputs are read from regular "
                   "files only");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
}

// A rosbag2 folder with MCAP storage, its metadata.yaml written by hand.
std::string McapFolder(const TempDir& dir, const std::string& metadata) {
  const std::string folder = dir.File("rosbag2");
  fs::create_directory(folder);
  std::string error;
  EXPECT_TRUE(testing::WriteRos2Bag(folder + "/rec_0.mcap", "--format=mcap", "", &error))
      << error;
  std::ofstream(folder + "/metadata.yaml") << metadata;
  return folder;
}

TEST(BagInput, McapStorageMetadataValuesMayBeQuoted) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  const std::string folder = McapFolder(
      dir, "rosbag2_bagfile_information:\n  version: 8\n  storage_identifier: 'mcap'\n"
           "  relative_file_paths:\n    - \"rec_0.mcap\"\n  compression_format: \"\"\n");
  std::unique_ptr<MessageReader> reader;
  const Status status = Open(folder, &reader);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(reader->TotalMessageCount(), 54);
  EXPECT_TRUE(reader->warnings().empty()) << Joined(reader->warnings());
}

TEST(BagInput, McapStorageCompressionFormatIsRefusedClearly) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  const std::string folder = McapFolder(
      dir, "rosbag2_bagfile_information:\n  storage_identifier: mcap\n"
           "  relative_file_paths:\n    - rec_0.mcap\n  compression_format: zstd\n"
           "  compression_mode: FILE\n");
  std::unique_ptr<MessageReader> reader;
  const Status status = Open(folder, &reader);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(folder + "/metadata.yaml: compression_format 'zstd': "
                                           "compressed rosbag2 bags are not supported"),
            std::string::npos)
      << status.message();
}

TEST(BagInput, McapStorageFilesNotListedAreNamedInAWarning) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  const std::string folder = McapFolder(
      dir, "rosbag2_bagfile_information:\n  storage_identifier: mcap\n"
           "  relative_file_paths:\n    - rec_0.mcap\n");
  fs::copy_file(folder + "/rec_0.mcap", folder + "/rec_1.mcap");
  std::unique_ptr<MessageReader> reader;
  const Status status = Open(folder, &reader);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(reader->TotalMessageCount(), 54);
  EXPECT_EQ(Joined(reader->warnings()),
            folder + ": 1 .mcap file(s) of the folder not listed in metadata.yaml, not read: "
                     "rec_1.mcap\n");
}

TEST(BagInput, McapStorageListingAMissingFileIsAnError) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  const std::string folder = McapFolder(
      dir, "rosbag2_bagfile_information:\n  storage_identifier: mcap\n"
           "  relative_file_paths:\n    - rec_0.mcap\n    - rec_1.mcap\n");
  std::unique_ptr<MessageReader> reader;
  const Status status = Open(folder, &reader);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(),
            folder + "/metadata.yaml: lists 'rec_1.mcap', which is not in " + folder);
}

TEST(BagInput, MetadataFifoIsRefusedAtOnce) {
  TempDir dir;
  const std::string folder = dir.File("rosbag2");
  fs::create_directory(folder);
  ASSERT_EQ(::mkfifo((folder + "/metadata.yaml").c_str(), 0600), 0);
  std::unique_ptr<MessageReader> reader;
  const auto start = std::chrono::steady_clock::now();
  const Status status = Open(folder, &reader);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(folder + "/metadata.yaml: a FIFO"), std::string::npos)
      << status.message();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
}

}  // namespace
}  // namespace tiltcal::bag
