#include "common/io/record_stream.h"

#include <cstdio>
#include <filesystem>
#include <vector>

#include <gtest/gtest.h>

#include "common/io/atomic_file.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/imu.pb.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal {
namespace {

using testing::TempDir;

proto::Scan MakeScan(int index, int num_points) {
  proto::Scan scan;
  scan.set_index(index);
  scan.set_stamp_ns(1'700'000'000'000'000'000LL + index * 100'000'000LL);
  for (int i = 0; i < num_points; ++i) {
    scan.add_x(0.5f * i);
    scan.add_y(-0.25f * i);
    scan.add_z(0.01f * index);
    scan.add_intensity(i % 256);
    scan.add_ring(i % 16);
    scan.add_time_offset_ns(-100'000'000 + i * 1000);
  }
  return scan;
}

// How a stream is written: plain, or one LZ4 frame built in one of the ways
// Lz4FrameOptions allows.
enum class Framing { kPlain, kLz4, kLz4Stored, kLz4NoChecksum, kLz4StoredNoChecksum };

void WriteScans(const std::string& path, Framing framing, int count, int points) {
  RecordWriter writer;
  proto::Provenance provenance;
  provenance.set_producer("record_stream_test");
  if (framing == Framing::kPlain) {
    ASSERT_TRUE(writer.Open(path, "tiltcal.proto.Scan", provenance, false).ok());
  } else {
    Lz4FrameOptions options;
    options.compress_blocks = framing == Framing::kLz4 || framing == Framing::kLz4NoChecksum;
    options.content_checksum = framing == Framing::kLz4 || framing == Framing::kLz4Stored;
    ASSERT_TRUE(writer.Open(path, "tiltcal.proto.Scan", provenance, options).ok());
  }
  for (int i = 0; i < count; ++i) ASSERT_TRUE(writer.Write(MakeScan(i, points)).ok());
  ASSERT_TRUE(writer.Close().ok());
}

void WriteScans(const std::string& path, bool compress, int count, int points) {
  WriteScans(path, compress ? Framing::kLz4 : Framing::kPlain, count, points);
}

class RecordStreamTest : public ::testing::TestWithParam<Framing> {};

TEST_P(RecordStreamTest, RoundTripKeepsEveryRecordAndTheHeader) {
  TempDir dir;
  const std::string path = dir.File("scans.binpb");
  WriteScans(path, GetParam(), 25, 3000);
  std::vector<proto::Scan> scans;
  proto::StreamHeader header;
  const Status status = ReadAllRecords<proto::Scan>(path, &scans, &header);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(header.payload_type(), "tiltcal.proto.Scan");
  EXPECT_EQ(header.provenance().producer(), "record_stream_test");
  ASSERT_EQ(scans.size(), 25u);
  for (int i = 0; i < 25; ++i) {
    EXPECT_EQ(scans[i].SerializeAsString(), MakeScan(i, 3000).SerializeAsString());
  }
}

TEST_P(RecordStreamTest, EmptyStreamEndsCleanly) {
  TempDir dir;
  const std::string path = dir.File("empty.binpb");
  WriteScans(path, GetParam(), 0, 0);
  std::vector<proto::Scan> scans;
  EXPECT_TRUE(ReadAllRecords<proto::Scan>(path, &scans).ok());
  EXPECT_TRUE(scans.empty());
}

TEST_P(RecordStreamTest, TruncatedFileIsAnErrorNamingFileAndRecord) {
  TempDir dir;
  const std::string path = dir.File("scans.binpb");
  WriteScans(path, GetParam(), 10, 2000);
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size - size / 3);
  std::vector<proto::Scan> scans;
  const Status status = ReadAllRecords<proto::Scan>(path, &scans);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(path), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("record " + std::to_string(scans.size())), std::string::npos)
      << status.message();
  EXPECT_LT(scans.size(), 10u);
}

TEST_P(RecordStreamTest, EveryCutIsAnErrorAlsoBetweenTwoRecords) {
  // Cut after every byte, record boundaries included: the end mark (and in
  // an LZ4 frame also the frame's own end mark) is then missing.
  TempDir dir;
  const std::string path = dir.File("scans.binpb");
  WriteScans(path, GetParam(), 3, 10);
  std::string bytes;
  ASSERT_TRUE(ReadFileToString(path, &bytes).ok());
  std::vector<proto::Scan> scans;
  ASSERT_TRUE(ReadAllRecords<proto::Scan>(path, &scans).ok());
  ASSERT_EQ(scans.size(), 3u);
  for (size_t length = 0; length < bytes.size(); ++length) {
    const std::string cut = dir.File("cut.binpb");
    ASSERT_TRUE(WriteFileAtomically(cut, bytes.substr(0, length)).ok());
    EXPECT_FALSE(ReadAllRecords<proto::Scan>(cut, &scans).ok()) << "cut after " << length;
  }
}

const char* FramingName(Framing framing) {
  switch (framing) {
    case Framing::kPlain: return "Plain";
    case Framing::kLz4: return "Lz4";
    case Framing::kLz4Stored: return "Lz4Stored";
    case Framing::kLz4NoChecksum: return "Lz4NoChecksum";
    case Framing::kLz4StoredNoChecksum: return "Lz4StoredNoChecksum";
  }
  return "?";
}

INSTANTIATE_TEST_SUITE_P(PlainAndLz4, RecordStreamTest,
                         ::testing::Values(Framing::kPlain, Framing::kLz4, Framing::kLz4Stored,
                                           Framing::kLz4NoChecksum,
                                           Framing::kLz4StoredNoChecksum),
                         [](const auto& info) { return FramingName(info.param); });

class Lz4FramingTest : public ::testing::TestWithParam<Framing> {};

TEST_P(Lz4FramingTest, StreamIsOneStandardLz4Frame) {
  if (testing::RunCommand("command -v lz4 >/dev/null") != 0) GTEST_SKIP() << "lz4 tool missing";
  TempDir dir;
  // 300 scans of 1000 points: ~5 MB, many 256 KiB blocks and a short last one.
  WriteScans(dir.File("a.binpb.lz4"), GetParam(), 300, 1000);
  WriteScans(dir.File("b.binpb"), Framing::kPlain, 300, 1000);
  ASSERT_EQ(testing::RunCommand("lz4 -dc " + dir.File("a.binpb.lz4") + " > " + dir.File("a.binpb")),
            0);
  std::string a, b;
  ASSERT_TRUE(ReadFileToString(dir.File("a.binpb"), &a).ok());
  ASSERT_TRUE(ReadFileToString(dir.File("b.binpb"), &b).ok());
  // Same content apart from the creation time in the header: compare records.
  std::vector<proto::Scan> from_a, from_b;
  ASSERT_TRUE(ReadAllRecords<proto::Scan>(dir.File("a.binpb"), &from_a).ok());
  ASSERT_TRUE(ReadAllRecords<proto::Scan>(dir.File("b.binpb"), &from_b).ok());
  ASSERT_EQ(from_a.size(), 300u);
  for (size_t i = 0; i < from_a.size(); ++i) {
    EXPECT_EQ(from_a[i].SerializeAsString(), from_b[i].SerializeAsString());
  }
}

INSTANTIATE_TEST_SUITE_P(Lz4, Lz4FramingTest,
                         ::testing::Values(Framing::kLz4, Framing::kLz4Stored,
                                           Framing::kLz4NoChecksum,
                                           Framing::kLz4StoredNoChecksum),
                         [](const auto& info) { return FramingName(info.param); });

TEST(RecordStream, StoredBlocksAreLargerThanCompressedOnes) {
  TempDir dir;
  WriteScans(dir.File("compressed.binpb.lz4"), Framing::kLz4, 20, 2000);
  WriteScans(dir.File("stored.binpb.lz4"), Framing::kLz4Stored, 20, 2000);
  WriteScans(dir.File("plain.binpb"), Framing::kPlain, 20, 2000);
  const auto compressed = std::filesystem::file_size(dir.File("compressed.binpb.lz4"));
  const auto stored = std::filesystem::file_size(dir.File("stored.binpb.lz4"));
  const auto plain = std::filesystem::file_size(dir.File("plain.binpb"));
  EXPECT_LT(compressed, plain);
  // Stored: 7 header bytes, 4 per block, the end mark and the checksum.
  EXPECT_EQ(stored, plain + 7 + 4 * ((plain + 256 * 1024 - 1) / (256 * 1024)) + 4 + 4);
}

// A stream of several write-behind windows (AtomicFile::WriteBehind): the
// device write of the completed windows has started before Close(), and the
// stream reads back whole.
TEST(RecordStream, LargeStreamStartsTheDeviceWriteBeforeClose) {
  TempDir dir;
  const std::string path = dir.File("scans.binpb.lz4");
  RecordWriter writer;
  Lz4FrameOptions stored;
  stored.compress_blocks = false;
  ASSERT_TRUE(writer.Open(path, "tiltcal.proto.Scan", proto::Provenance(), stored).ok());
  // 40 scans of 30,000 points: ~25 MiB, three windows.
  constexpr int kScans = 40, kPoints = 30000;
  for (int i = 0; i < kScans; ++i) ASSERT_TRUE(writer.Write(MakeScan(i, kPoints)).ok());
  EXPECT_GE(writer.file()->write_behind_bytes(), 2 * kWriteBehindBytes);
  ASSERT_TRUE(writer.Close().ok());
  const auto size = static_cast<long long>(std::filesystem::file_size(path));
  ASSERT_GE(size, 3 * kWriteBehindBytes);
  std::vector<proto::Scan> scans;
  const Status status = ReadAllRecords<proto::Scan>(path, &scans);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(scans.size(), static_cast<size_t>(kScans));
  EXPECT_EQ(scans.back().SerializeAsString(), MakeScan(kScans - 1, kPoints).SerializeAsString());
}

TEST(RecordStream, CorruptByteOfStoredBlocksFailsTheContentChecksum) {
  TempDir dir;
  const std::string path = dir.File("scans.binpb.lz4");
  WriteScans(path, Framing::kLz4Stored, 5, 500);
  std::string bytes;
  ASSERT_TRUE(ReadFileToString(path, &bytes).ok());
  bytes[bytes.size() / 2] ^= 0x01;  // a float of a column: still parses
  ASSERT_TRUE(WriteFileAtomically(path, bytes).ok());
  std::vector<proto::Scan> scans;
  const Status status = ReadAllRecords<proto::Scan>(path, &scans);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(path), std::string::npos) << status.message();
}

TEST(RecordStream, WrongMagicIsRejected) {
  TempDir dir;
  ASSERT_TRUE(WriteFileAtomically(dir.File("junk"), "#ROSBAG V2.0\nxxxxxxxx").ok());
  RecordReader reader;
  const Status status = reader.Open(dir.File("junk"));
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("not a tiltcal record stream"), std::string::npos);
}

TEST(RecordStream, WrongPayloadTypeIsRejected) {
  TempDir dir;
  WriteScans(dir.File("scans.binpb"), false, 1, 1);
  std::vector<proto::ImuSample> imu;
  const Status status = ReadAllRecords<proto::ImuSample>(dir.File("scans.binpb"), &imu);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("expected tiltcal.proto.ImuSample"), std::string::npos);
}

TEST(RecordStream, CorruptCompressedByteIsAnError) {
  TempDir dir;
  const std::string path = dir.File("scans.binpb.lz4");
  WriteScans(path, true, 5, 500);
  std::string bytes;
  ASSERT_TRUE(ReadFileToString(path, &bytes).ok());
  bytes[bytes.size() / 2] ^= 0x5A;
  ASSERT_TRUE(WriteFileAtomically(path, bytes).ok());
  std::vector<proto::Scan> scans;
  EXPECT_FALSE(ReadAllRecords<proto::Scan>(path, &scans).ok());
}

// A plain stream of 3 scans ends with its end mark: 0x00 (zero length), then
// the StreamEnd (2 bytes: field 1 varint 3).
TEST(RecordStream, EndMarkCountingOtherRecordsIsAnError) {
  TempDir dir;
  const std::string path = dir.File("scans.binpb");
  WriteScans(path, false, 3, 10);
  std::string bytes;
  ASSERT_TRUE(ReadFileToString(path, &bytes).ok());
  ASSERT_EQ(bytes.substr(bytes.size() - 4), std::string("\x00\x02\x08\x03", 4));
  bytes.back() = '\x05';
  ASSERT_TRUE(WriteFileAtomically(path, bytes).ok());
  std::vector<proto::Scan> scans;
  const Status status = ReadAllRecords<proto::Scan>(path, &scans);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("counts 5 records, the stream holds 3"), std::string::npos)
      << status.message();
}

TEST(RecordStream, DataAfterTheEndMarkIsAnError) {
  TempDir dir;
  const std::string path = dir.File("scans.binpb");
  WriteScans(path, false, 2, 10);
  std::string bytes;
  ASSERT_TRUE(ReadFileToString(path, &bytes).ok());
  ASSERT_TRUE(WriteFileAtomically(path, bytes + "x").ok());
  std::vector<proto::Scan> scans;
  const Status status = ReadAllRecords<proto::Scan>(path, &scans);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("data after the end mark"), std::string::npos)
      << status.message();
}

TEST(RecordStream, StreamOfAnOlderFormatVersionIsRefusedWithWhatToDo) {
  // Format version 1 had no end mark: such a file cannot be trusted to be whole.
  TempDir dir;
  proto::StreamHeader header;
  header.set_payload_type("tiltcal.proto.Scan");
  header.set_format_version(1);
  const std::string body = header.SerializeAsString();
  ASSERT_LT(body.size(), 128u);
  const std::string path = dir.File("scans.binpb");
  ASSERT_TRUE(WriteFileAtomically(path, std::string(kStreamMagic, sizeof(kStreamMagic)) +
                                            static_cast<char>(body.size()) + body)
                  .ok());
  std::vector<proto::Scan> scans;
  const Status status = ReadAllRecords<proto::Scan>(path, &scans);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("unsupported stream format version 1"), std::string::npos)
      << status.message();
  EXPECT_NE(status.message().find("rerun the stage that wrote it"), std::string::npos)
      << status.message();
}

TEST(RecordStream, EmptyRecordIsRefusedByTheWriter) {
  TempDir dir;
  RecordWriter writer;
  ASSERT_TRUE(writer.Open(dir.File("imu.binpb"), "tiltcal.proto.ImuSample", {}, false).ok());
  const Status status = writer.Write(proto::ImuSample());
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("record 0 is empty"), std::string::npos) << status.message();
}

TEST(RecordStream, UnclosedWriterLeavesNoFile) {
  TempDir dir;
  const std::string path = dir.File("scans.binpb");
  {
    RecordWriter writer;
    ASSERT_TRUE(writer.Open(path, "tiltcal.proto.Scan", {}, true).ok());
    ASSERT_TRUE(writer.Write(MakeScan(0, 10)).ok());
  }  // destroyed without Close()
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

}  // namespace
}  // namespace tiltcal
