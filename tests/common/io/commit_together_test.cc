// CommitTogether: every state a kill can leave is either the old set of
// outputs, the new set, or manifests that readers refuse and that
// CompleteInterruptedCommit turns into the new set.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "common/io/atomic_file.h"
#include "common/io/record_stream.h"
#include "tests/testing/test_env.h"

namespace tiltcal {
namespace {

namespace fs = std::filesystem;

std::string Contents(const std::string& path) {
  std::string contents;
  return ReadFileToString(path, &contents).ok() ? contents : "(absent)";
}

// A record stream holding one provenance note `note`, committed at `path`.
void WriteStream(const std::string& path, const std::string& note) {
  proto::Provenance provenance;
  provenance.add_notes(note);
  RecordWriter writer;
  ASSERT_TRUE(writer.Open(path, "tiltcal.proto.ImuSample", provenance, false).ok());
  ASSERT_TRUE(writer.Close().ok());
}

TEST(CommitTogether, BothFilesAppearAndNoManifestStays) {
  testing::TempDir dir;
  AtomicFile a, b;
  ASSERT_TRUE(a.Open(dir.File("a")).ok());
  ASSERT_TRUE(b.Open(dir.File("b")).ok());
  std::fputs("new a", a.file());
  std::fputs("new b", b.file());
  ASSERT_TRUE(CommitTogether({&a, &b}).ok());
  EXPECT_EQ(Contents(dir.File("a")), "new a");
  EXPECT_EQ(Contents(dir.File("b")), "new b");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), {}), 2);
}

// The state of a run killed after its manifests were written and the first
// rename done: a new `a`, the old `b`, b's temporary and both manifests.
TEST(CommitTogether, AKillBetweenTheRenamesIsRefusedThenCompleted) {
  testing::TempDir dir;
  const std::string a = dir.File("imu.binpb"), b = dir.File("scans.binpb");
  WriteStream(a, "old");
  WriteStream(b, "old");
  const std::string temp_b = b + ".tmp.999999999";
  WriteStream(dir.File("new_b"), "new");
  fs::rename(dir.File("new_b"), temp_b);
  const std::string manifest = fs::absolute(a + ".tmp.999999998").string() + "\t" +
                               fs::absolute(a).string() + "\n" + fs::absolute(temp_b).string() +
                               "\t" + fs::absolute(b).string() + "\n";
  ASSERT_TRUE(WriteFileAtomically(CommitManifestPath(a), manifest).ok());
  ASSERT_TRUE(WriteFileAtomically(CommitManifestPath(b), manifest).ok());
  WriteStream(a, "new");  // the first rename happened

  RecordReader reader;
  const Status refused = reader.Open(b);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find(b + ": its writer was interrupted"), std::string::npos)
      << refused.message();
  EXPECT_FALSE(reader.Open(a).ok());

  ASSERT_TRUE(CompleteInterruptedCommit(b).ok());
  EXPECT_FALSE(fs::exists(CommitManifestPath(a)));
  EXPECT_FALSE(fs::exists(CommitManifestPath(b)));
  EXPECT_FALSE(fs::exists(temp_b));
  for (const std::string& path : {a, b}) {
    ASSERT_TRUE(reader.Open(path).ok()) << path;
    EXPECT_EQ(reader.header().provenance().notes(0), "new") << path;
  }
  EXPECT_TRUE(CompleteInterruptedCommit(a).ok());  // nothing left to do
}

TEST(CommitTogether, ACorruptManifestIsAnErrorNamingIt) {
  testing::TempDir dir;
  ASSERT_TRUE(WriteFileAtomically(CommitManifestPath(dir.File("a")), "garbage\n").ok());
  const Status status = CompleteInterruptedCommit(dir.File("a"));
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(dir.File("a.commit") + ": not a commit manifest"),
            std::string::npos)
      << status.message();
}

TEST(AtomicFile, OpenRemovesTemporariesOfDeadProcessesOnly) {
  testing::TempDir dir;
  const std::string path = dir.File("out.txt");
  std::ofstream(path + ".tmp.999999999") << "killed run";  // above any pid_max
  std::ofstream(path + ".tmp.1") << "init's";              // pid 1 runs
  std::ofstream(path + ".tmp.x1") << "not ours";
  std::ofstream(dir.File("other.txt.tmp.999999999")) << "another output's";
  AtomicFile file;
  ASSERT_TRUE(file.Open(path).ok());
  EXPECT_FALSE(fs::exists(path + ".tmp.999999999"));
  EXPECT_TRUE(fs::exists(path + ".tmp.1"));
  EXPECT_TRUE(fs::exists(path + ".tmp.x1"));
  EXPECT_TRUE(fs::exists(dir.File("other.txt.tmp.999999999")));
}

TEST(CheckOutputPath, NamesTheMissingDirectoryAndRefusesADirectory) {
  testing::TempDir dir;
  EXPECT_TRUE(CheckOutputPath(dir.File("out.txt")).ok());
  const Status missing = CheckOutputPath(dir.File("nope/out.txt"));
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.message(), dir.File("nope/out.txt") + ": cannot write output: directory " +
                                   dir.File("nope") + " does not exist");
  const Status directory = CheckOutputPath(dir.path());
  ASSERT_FALSE(directory.ok());
  EXPECT_NE(directory.message().find("it is a directory"), std::string::npos);
}

}  // namespace
}  // namespace tiltcal
