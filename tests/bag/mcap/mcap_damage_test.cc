// The MCAP reader on damaged files: files written by the official MCAP
// library (tests/oracle/write_ros2_bags.mjs) with one record's length
// overwritten (2^64-1, or 5 more than it is), a summary that omits one
// ChunkIndex, and chunks made here that decompress to far more than the
// reader's limit. Nothing is lost without a warning: every message outside
// the damaged record is read, and what was skipped is said.
#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "bag/mcap/format.h"
#include "bag/mcap/mcap_reader.h"
#include "tests/bag/ros2/ros2_oracle.h"
#include "tests/testing/test_env.h"

namespace tiltcal::mcap {
namespace {

using testing::TempDir;

#define SKIP_WITHOUT_ORACLE()                                   \
  if (const std::string missing = testing::Ros2OracleMissing(); \
      !missing.empty()) {                                       \
    GTEST_SKIP() << missing;                                    \
  }

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

uint64_t U64At(const std::string& bytes, size_t at) {
  uint64_t v = 0;
  std::memcpy(&v, bytes.data() + at, 8);
  return v;
}

void PutU64(std::string* bytes, size_t at, uint64_t v) { std::memcpy(&(*bytes)[at], &v, 8); }

struct Record {
  uint8_t opcode;
  uint64_t offset;
};

// The records of the data section (after the Header, up to DataEnd), and
// of the summary when `from` points to it.
std::vector<Record> Records(const std::string& bytes, uint64_t from = 8) {
  std::vector<Record> records;
  for (uint64_t at = from; at + 9 <= bytes.size();) {
    const auto opcode = static_cast<uint8_t>(bytes[at]);
    records.push_back({opcode, at});
    if (opcode == kDataEnd || opcode == kFooter) break;
    at += 9 + U64At(bytes, at + 1);
  }
  return records;
}

// One message as read: topic, log time, its bytes, and where it was.
struct ReadMessage {
  std::string key;  // topic, time, bytes
  uint64_t position;
};

std::vector<ReadMessage> ReadAll(McapReader* reader) {
  std::vector<ReadMessage> out;
  const Status status = reader->ReadMessages({}, [&](const bag::Message& m) {
    out.push_back({*m.topic + " " + std::to_string(m.time_ns) + " " +
                       std::string(reinterpret_cast<const char*>(m.data), m.size),
                   m.position});
    return Status::Ok();
  });
  EXPECT_TRUE(status.ok()) << status.message();
  return out;
}

std::string Joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& line : lines) out += line + "\n";
  return out;
}

// Writes the oracle's bag with `args`, then overwrites the length of the
// `which`-th data-section record of opcode `opcode` by `length(old)`, and
// checks that every message outside that record is read (a chunk whose own
// fields give its length is read whole), nothing that the intact file does
// not hold, and a warning names the damaged record.
template <typename NewLength>
void CheckDamagedLength(const std::string& args, uint8_t opcode, size_t which,
                        NewLength length) {
  TempDir dir;
  const std::string intact = dir.File("intact.mcap");
  const std::string damaged = dir.File("damaged.mcap");
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(intact, args, "", &error)) << error;
  std::string bytes = ReadBytes(intact);
  std::vector<Record> of_opcode;
  for (const Record& r : Records(bytes)) {
    if (r.opcode == opcode) of_opcode.push_back(r);
  }
  ASSERT_GT(of_opcode.size(), which + 1) << "the damaged record must not be the last";
  const uint64_t at = of_opcode[which].offset;
  const uint64_t old_length = U64At(bytes, at + 1);
  PutU64(&bytes, at + 1, length(old_length));
  WriteBytes(damaged, bytes);

  McapReader whole;
  ASSERT_TRUE(whole.Open(intact).ok());
  const std::vector<ReadMessage> all = ReadAll(&whole);
  std::vector<std::string> outside;  // the messages outside the damaged record
  for (const ReadMessage& m : all) {
    if (m.position != at) outside.push_back(m.key);  // the chunk's or the record's offset
  }
  ASSERT_LT(outside.size(), all.size());

  McapReader reader;
  const Status status = reader.Open(damaged);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(reader.salvage_note(), "");  // the file is complete: not cut short
  const std::string warnings = Joined(reader.warnings());
  EXPECT_NE(warnings.find(damaged + ": damaged "), std::string::npos) << warnings;
  EXPECT_NE(warnings.find("at byte " + std::to_string(at)), std::string::npos) << warnings;
  // Skipped bytes are counted; a chunk read with the length of its fields
  // skips nothing.
  EXPECT_TRUE(warnings.find("messages read from the rest of the file") != std::string::npos ||
              warnings.find("nothing skipped") != std::string::npos)
      << warnings;
  std::vector<std::string> read;
  for (const ReadMessage& m : ReadAll(&reader)) read.push_back(m.key);
  EXPECT_EQ(reader.TotalMessageCount(), static_cast<int64_t>(read.size()));
  // Everything outside the damaged record, and nothing the file does not hold.
  std::vector<std::string> all_keys;
  for (const ReadMessage& m : all) all_keys.push_back(m.key);
  std::sort(all_keys.begin(), all_keys.end());
  std::sort(read.begin(), read.end());
  std::sort(outside.begin(), outside.end());
  EXPECT_TRUE(std::includes(read.begin(), read.end(), outside.begin(), outside.end()))
      << read.size() << " read, " << outside.size() << " outside the damaged record\n"
      << warnings;
  EXPECT_TRUE(std::includes(all_keys.begin(), all_keys.end(), read.begin(), read.end()))
      << "a message read that the intact file does not hold";
}

uint64_t AllOnes(uint64_t) { return UINT64_MAX; }
uint64_t PlusFive(uint64_t length) { return length + 5; }

TEST(McapDamage, ChunkLengthOfAllOnesInAFileWithoutSummary) {
  SKIP_WITHOUT_ORACLE();
  CheckDamagedLength("--format=mcap --compression=zstd --no-summary", kChunk, 0, AllOnes);
}

TEST(McapDamage, ChunkLengthFiveTooLongInAFileWithoutSummary) {
  SKIP_WITHOUT_ORACLE();
  CheckDamagedLength("--format=mcap --compression=lz4 --no-summary", kChunk, 0, PlusFive);
}

TEST(McapDamage, UncompressedChunkLengthDamagedInAFileWithoutSummary) {
  SKIP_WITHOUT_ORACLE();
  CheckDamagedLength("--format=mcap --compression=none --no-summary", kChunk, 0, AllOnes);
  CheckDamagedLength("--format=mcap --compression=none --no-summary", kChunk, 0, PlusFive);
}

TEST(McapDamage, MessageLengthDamagedInAFileWithoutChunks) {
  SKIP_WITHOUT_ORACLE();
  CheckDamagedLength("--format=mcap --no-chunks --no-summary", kMessage, 20, AllOnes);
  CheckDamagedLength("--format=mcap --no-chunks --no-summary", kMessage, 20, PlusFive);
}

// A chunk whose records_size is damaged too cannot be read: it is skipped
// to the next record, and the messages after it whose Channel record was in
// it (the writer defines each channel once, in the first chunk that uses
// it) are counted and left out, their topic unknown.
TEST(McapDamage, ChunkWithItsFieldsDamagedIsSkippedAndWhatItDefinedIsCounted) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  const std::string intact = dir.File("intact.mcap");
  const std::string damaged = dir.File("damaged.mcap");
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(intact, "--format=mcap --compression=zstd --no-summary", "",
                                    &error))
      << error;
  std::string bytes = ReadBytes(intact);
  std::vector<uint64_t> chunks;
  for (const Record& r : Records(bytes)) {
    if (r.opcode == kChunk) chunks.push_back(r.offset);
  }
  ASSERT_EQ(chunks.size(), 2u);
  const uint64_t at = chunks[0];
  PutU64(&bytes, at + 1, UINT64_MAX);
  PutU64(&bytes, at + 9 + 8 + 8 + 8 + 4 + 4 + 4, UINT64_MAX);  // records_size ("zstd")
  WriteBytes(damaged, bytes);
  McapReader whole;
  ASSERT_TRUE(whole.Open(intact).ok());
  int64_t in_second = 0;
  for (const ReadMessage& m : ReadAll(&whole)) in_second += m.position == chunks[1];
  ASSERT_GT(in_second, 0);

  McapReader reader;
  const Status status = reader.Open(damaged);
  ASSERT_TRUE(status.ok()) << status.message();
  const std::string warnings = Joined(reader.warnings());
  EXPECT_NE(warnings.find(damaged + ": damaged the Chunk record at byte " + std::to_string(at)),
            std::string::npos)
      << warnings;
  EXPECT_NE(warnings.find("bytes " + std::to_string(at) + " to " + std::to_string(chunks[1]) +
                          " skipped"),
            std::string::npos)
      << warnings;
  EXPECT_NE(warnings.find(damaged + ": " + std::to_string(in_second) +
                          " messages on channels that no Channel record defines left out"),
            std::string::npos)
      << warnings;
  EXPECT_EQ(reader.TotalMessageCount(), 0);
}

// A file cut short is still salvaged up to the record that runs past its
// end (no Footer: nothing says where the data ends).
TEST(McapDamage, ACutShortFileIsSalvagedNotResynchronised) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  const std::string bag = dir.File("bag.mcap");
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(bag, "--format=mcap --no-chunks --no-summary", "", &error))
      << error;
  std::filesystem::resize_file(bag, std::filesystem::file_size(bag) / 2);
  McapReader reader;
  ASSERT_TRUE(reader.Open(bag).ok());
  EXPECT_NE(reader.salvage_note().find("the recording ends inside"), std::string::npos);
  EXPECT_TRUE(reader.warnings().empty()) << Joined(reader.warnings());
}

// The summary lists one chunk fewer than the data section holds (its
// ChunkIndex record turned into a private record, which readers skip): the
// chunk is read from the data section, with a warning.
TEST(McapDamage, SummaryOmittingAChunkIndexLosesNothing) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  const std::string bag = dir.File("bag.mcap");
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(bag, "--format=mcap --compression=zstd",
                                    dir.File("expected.txt"), &error))
      << error;
  std::string bytes = ReadBytes(bag);
  const uint64_t footer = bytes.size() - 8 - 29;
  const uint64_t summary_start = U64At(bytes, footer + 9);
  ASSERT_GT(summary_start, 0u);
  std::vector<uint64_t> chunk_indexes;
  for (const Record& r : Records(bytes, summary_start)) {
    if (r.offset >= footer) break;
    if (r.opcode == kChunkIndex) chunk_indexes.push_back(r.offset);
  }
  ASSERT_GE(chunk_indexes.size(), 2u);
  bytes[chunk_indexes[1]] = static_cast<char>(0x80);  // no longer a ChunkIndex
  WriteBytes(bag, bytes);

  McapReader reader;
  const Status status = reader.Open(bag);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_TRUE(reader.used_summary());
  const std::string warnings = Joined(reader.warnings());
  EXPECT_NE(warnings.find("the summary disagrees with the data section: it lists " +
                          std::to_string(chunk_indexes.size() - 1) + " chunks, the data "
                          "section holds " + std::to_string(chunk_indexes.size())),
            std::string::npos)
      << warnings;
  EXPECT_EQ(reader.TotalMessageCount(), 54);
  int count = 0;
  EXPECT_EQ(testing::CompareWithExpected(&reader, dir.File("expected.txt"), &count), "");
  EXPECT_EQ(count, 54);
}

// An intact file has no warning on either path.
TEST(McapDamage, IntactFilesHaveNoWarning) {
  SKIP_WITHOUT_ORACLE();
  for (const char* args : {"--format=mcap --compression=zstd", "--format=mcap --no-summary",
                           "--format=mcap --no-chunks --no-summary"}) {
    TempDir dir;
    const std::string bag = dir.File("bag.mcap");
    std::string error;
    ASSERT_TRUE(testing::WriteRos2Bag(bag, args, "", &error)) << error;
    McapReader reader;
    ASSERT_TRUE(reader.Open(bag).ok()) << args;
    EXPECT_TRUE(reader.warnings().empty()) << args << ": " << Joined(reader.warnings());
    EXPECT_EQ(reader.TotalMessageCount(), 54) << args;
  }
}

// ---- chunks that decompress to far more than the limit ----

std::string Record(uint8_t opcode, const std::string& content) {
  std::string r(1, static_cast<char>(opcode));
  r.append(8, '\0');
  PutU64(&r, 1, content.size());
  return r + content;
}

std::string U32(uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); }
std::string U64(uint64_t v) { return std::string(reinterpret_cast<const char*>(&v), 8); }
std::string Str(const std::string& s) { return U32(static_cast<uint32_t>(s.size())) + s; }

// One zstd frame of `blocks` RLE blocks of 128 KiB of zeros: 4 bytes per
// block (the most one compressed byte can give), no content size.
std::string ZstdZeros(uint64_t blocks) {
  std::string frame = std::string("\x28\xB5\x2F\xFD", 4) + std::string("\x00\x38", 2);
  for (uint64_t b = 0; b < blocks; ++b) {
    const uint32_t header = (b + 1 == blocks ? 1u : 0u) | (1u << 1) | (131072u << 3);
    frame += std::string(reinterpret_cast<const char*>(&header), 3) + std::string(1, '\0');
  }
  return frame;
}

// An MCAP file with one zstd chunk of `blocks` x 128 KiB of zeros, no summary.
std::string McapWithZeroChunk(uint64_t blocks) {
  const std::string magic("\x89MCAP0\r\n", 8);
  const std::string frame = ZstdZeros(blocks);
  const std::string chunk = U64(0) + U64(0) + U64(blocks * 131072) + U32(0) + Str("zstd") +
                            U64(frame.size()) + frame;
  return magic + Record(kHeader, Str("ros2") + Str("")) + Record(kChunk, chunk) +
         Record(kDataEnd, U32(0)) + Record(kFooter, U64(0) + U64(0) + U32(0)) + magic;
}

TEST(McapDamage, ChunkBeyondTheLimitIsRefusedBeforeItIsDecompressed) {
  TempDir dir;
  // 512 MiB (within every check of the format: 4 bytes per 128 KiB block)
  // and 4 GiB - 128 KiB, against the default limit of 256 MiB.
  for (const uint64_t blocks : {uint64_t{4096}, uint64_t{32767}}) {
    const std::string bag = dir.File("zeros_" + std::to_string(blocks) + ".mcap");
    WriteBytes(bag, McapWithZeroChunk(blocks));
    const auto start = std::chrono::steady_clock::now();
    McapReader reader;
    const Status status = reader.Open(bag);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_FALSE(status.ok()) << blocks;
    EXPECT_NE(status.message().find(bag + ": byte "), std::string::npos) << status.message();
    EXPECT_NE(status.message().find("beyond the limit of 268435456 bytes"), std::string::npos)
        << status.message();
    EXPECT_LT(seconds, 1.0);  // refused before anything is decompressed
  }
}

TEST(McapDamage, ChunkLimitIsTheCallers) {
  TempDir dir;
  const std::string bag = dir.File("zeros.mcap");
  WriteBytes(bag, McapWithZeroChunk(16));  // 2 MiB
  {
    McapReader reader(uint64_t{1} << 20);
    const Status status = reader.Open(bag);
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.message().find("beyond the limit of 1048576 bytes"), std::string::npos)
        << status.message();
  }
  // Within the limit the chunk is decompressed (its zeros are no records:
  // the error after it is the records', not the limit's).
  McapReader reader(uint64_t{4} << 20);
  const Status status = reader.Open(bag);
  EXPECT_EQ(status.message().find("beyond the limit"), std::string::npos) << status.message();
  EXPECT_EQ(reader.chunks_decompressed(), 1u);
}

}  // namespace
}  // namespace tiltcal::mcap
