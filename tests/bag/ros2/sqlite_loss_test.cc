// The rosbag2 sqlite3 reader returns every message the folder holds, or
// says what it left out: messages still in a -wal file (a recorder stopped
// before its checkpoint), .db3 files that metadata.yaml does not list, rows
// whose timestamp is not an integer; negative timestamps and metadata.yaml
// files that are not regular files (a FIFO, /dev/zero) are errors. Bags
// written by the npm oracle (tests/oracle/write_ros2_bags.mjs), then changed
// here with libsqlite3.
#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bag/ros2/sqlite_bag_reader.h"
#include "tests/bag/ros2/ros2_oracle.h"
#include "tests/testing/test_env.h"

namespace tiltcal::ros2 {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

#define SKIP_WITHOUT_ORACLE()                                   \
  if (const std::string missing = testing::Ros2OracleMissing(); \
      !missing.empty()) {                                       \
    GTEST_SKIP() << missing;                                    \
  }

// Runs `sql` on the database `file`; fails the test on an error.
void Execute(sqlite3* db, const std::string& sql) {
  char* error = nullptr;
  const int rc = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error);
  EXPECT_EQ(rc, SQLITE_OK) << sql << ": " << (error ? error : "");
  sqlite3_free(error);
}

void ExecuteOn(const std::string& file, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  Execute(db, sql);
  sqlite3_close(db);
}

std::string Joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& line : lines) out += line + "\n";
  return out;
}

int64_t CountRead(SqliteBagReader* reader) {
  int64_t n = 0;
  const Status status = reader->ReadMessages({}, [&](const bag::Message&) {
    ++n;
    return Status::Ok();
  });
  EXPECT_TRUE(status.ok()) << status.message();
  return n;
}

// A bag whose last 30 messages are only in the WAL: the database is put in
// WAL mode, its rows past id 24 moved out and checkpointed away, then put
// back without a checkpoint; the folder is copied while the writer still
// has it open (as a recorder killed at that moment leaves it).
TEST(SqliteLoss, MessagesInTheWalAreRead) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  const std::string bag = dir.File("bag");
  std::string error;
  ASSERT_TRUE(
      testing::WriteRos2Bag(bag, "--format=sqlite3", dir.File("expected.txt"), &error))
      << error;
  const std::string db3 = bag + "/bag_0.db3";
  ASSERT_TRUE(testing::FileExists(db3));
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(db3.c_str(), &db), SQLITE_OK);
  Execute(db, "PRAGMA journal_mode=WAL; PRAGMA wal_autocheckpoint=0;"
              "CREATE TABLE later AS SELECT * FROM messages WHERE id > 24;"
              "DELETE FROM messages WHERE id > 24; PRAGMA wal_checkpoint(TRUNCATE);"
              "INSERT INTO messages SELECT * FROM later; DROP TABLE later;");
  const std::string killed = dir.File("killed");
  fs::create_directory(killed);
  for (const fs::directory_entry& e : fs::directory_iterator(bag)) {
    fs::copy_file(e.path(), killed + "/" + e.path().filename().string());
  }
  sqlite3_close(db);
  ASSERT_TRUE(testing::FileExists(killed + "/bag_0.db3-wal"));
  ASSERT_GT(fs::file_size(killed + "/bag_0.db3-wal"), 0u);

  SqliteBagReader reader;
  const Status status = reader.Open(killed);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(reader.TotalMessageCount(), 54);
  int count = 0;
  EXPECT_EQ(testing::CompareWithExpected(&reader, dir.File("expected.txt"), &count), "");
  EXPECT_EQ(count, 54);
  EXPECT_TRUE(reader.warnings().empty()) << Joined(reader.warnings());
}

// A .db3 in the folder that metadata.yaml does not list is named.
TEST(SqliteLoss, UnlistedDb3FilesAreNamedInAWarning) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  const std::string bag = dir.File("bag");
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(bag, "--format=sqlite3 --split=20", "", &error)) << error;
  fs::copy_file(bag + "/bag_0.db3", bag + "/extra_recording.db3");
  SqliteBagReader reader;
  const Status status = reader.Open(bag);
  ASSERT_TRUE(status.ok()) << status.message();
  const std::string warnings = Joined(reader.warnings());
  EXPECT_NE(warnings.find(bag + ": 1 .db3 file(s) of the folder not listed in metadata.yaml, "
                                "not read: extra_recording.db3"),
            std::string::npos)
      << warnings;
  EXPECT_EQ(reader.TotalMessageCount(), 54);
}

// NULL, text and real timestamps: left out, counted, their rows named, and
// the counts agree with what is read.
TEST(SqliteLoss, RowsWithoutAnIntegerTimestampAreCountedAndNamed) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  const std::string bag = dir.File("bag");
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(bag, "--format=sqlite3", "", &error)) << error;
  // rosbag2's schema says NOT NULL; a table without the constraint (a
  // hand-made or damaged file) can hold any value.
  ExecuteOn(bag + "/bag_0.db3",
            "CREATE TABLE loose AS SELECT * FROM messages; DROP TABLE messages;"
            "ALTER TABLE loose RENAME TO messages;"
            "UPDATE messages SET timestamp = NULL WHERE id = 3;"
            "UPDATE messages SET timestamp = 'soon' WHERE id = 7;"
            "UPDATE messages SET timestamp = 1.5 WHERE id = 11;");
  SqliteBagReader reader;
  const Status status = reader.Open(bag);
  ASSERT_TRUE(status.ok()) << status.message();
  const std::string warnings = Joined(reader.warnings());
  EXPECT_NE(warnings.find(bag + "/bag_0.db3: 3 message(s) without an integer timestamp left out"),
            std::string::npos)
      << warnings;
  EXPECT_NE(warnings.find("rows 3 (null), 7 (text), 11 (real)"), std::string::npos) << warnings;
  EXPECT_EQ(reader.TotalMessageCount(), 51);
  EXPECT_EQ(CountRead(&reader), 51);
}

// Negative timestamps (before 1970): an error naming the file and a row.
TEST(SqliteLoss, NegativeTimestampsAreAnErrorNamingTheRow) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  const std::string bag = dir.File("bag");
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(bag, "--format=sqlite3", "", &error)) << error;
  ExecuteOn(bag + "/bag_0.db3", "UPDATE messages SET timestamp = -timestamp;");
  SqliteBagReader reader;
  const Status status = reader.Open(bag);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(bag + "/bag_0.db3: row 1 has a negative timestamp"),
            std::string::npos)
      << status.message();
}

// metadata.yaml as a FIFO (nobody writes it) or a link to /dev/zero: refused
// at once, without reading.
TEST(SqliteLoss, MetadataThatIsNotARegularFileIsRefusedAtOnce) {
  TempDir dir;
  const std::string fifo_bag = dir.File("fifo_bag");
  fs::create_directory(fifo_bag);
  ASSERT_EQ(::mkfifo((fifo_bag + "/metadata.yaml").c_str(), 0600), 0);
  const std::string zero_bag = dir.File("zero_bag");
  fs::create_directory(zero_bag);
  fs::create_symlink("/dev/zero", zero_bag + "/metadata.yaml");
  for (const std::string& bag : {fifo_bag, zero_bag}) {
    const auto start = std::chrono::steady_clock::now();
    SqliteBagReader reader;
    const Status status = reader.Open(bag);
    ASSERT_FALSE(status.ok()) << bag;
    EXPECT_NE(status.message().find(bag + "/metadata.yaml: a "), std::string::npos)
        << status.message();
    EXPECT_NE(status.message().find("not a regular file"), std::string::npos) << status.message();
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
              1.0);
  }
}

}  // namespace
}  // namespace tiltcal::ros2
