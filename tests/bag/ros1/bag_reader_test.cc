// The reader on small bags assembled here record by record (format.h's
// writer side), for the cases the public and python-written bags lack:
// several connections on one topic, time ties, encrypted bags, broken
// indexes, eviction from a one-chunk cache, truncation and byte flips.
#include "bag/ros1/bag_reader.h"

#include <sys/resource.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bag/ros1/bag_writer.h"
#include "tests/testing/test_env.h"

namespace tiltcal::ros1 {
namespace {

struct Conn {
  uint32_t id;
  std::string topic;
  std::string type;
};
struct Msg {
  uint32_t conn;
  int64_t time_ns;
  std::string data;
};

struct BagOptions {
  std::string compression = "none";
  std::string encryptor;
  uint32_t chunk_info_version = 1;
  int index_count_delta = 0;  // added to the count of the first index data record
  bool indexed = true;        // false: index_pos 0 and no index section
  // Non-empty: the last chunk is still open (size 0, data_len 0), as a killed
  // recorder leaves it; "none" keeps its records after the header, any other
  // compression keeps only a 7-byte frame start.
  std::string open_last_chunk_compression;
  // Non-zero: the size the chunk records declare instead of their true one.
  uint32_t declared_chunk_size = 0;
};

std::string Time(int64_t ns) {
  RosTime t;
  EXPECT_TRUE(NsToRosTime(ns, &t));
  return TimeValue(t);
}

// A v2.0 bag with uncompressed chunks laid out as rosbag writes them.
std::string BuildBag(const std::vector<Conn>& conns, const std::vector<std::vector<Msg>>& chunks,
                     const BagOptions& options = {}) {
  const uint64_t body_start = kVersionLine.size() + 8 + kBagHeaderPaddedSize;
  auto connection_record = [&](const Conn& c, std::string* out) {
    HeaderFields inner{{"topic", c.topic},
                       {"type", c.type},
                       {"md5sum", "*"},
                       {"message_definition", "# test\n"}};
    AppendRecord(out, {{"op", OpValue(Op::kConnection)}, {"conn", U32Value(c.id)},
                       {"topic", c.topic}},
                 BuildHeader(inner));
  };
  std::string body;
  std::set<uint32_t> written;
  struct Info {
    uint64_t pos;
    int64_t start, end;
    std::map<uint32_t, uint32_t> counts;
  };
  std::vector<Info> infos;
  bool first_index = true;
  for (const std::vector<Msg>& chunk : chunks) {
    std::string data;
    std::map<uint32_t, std::string> index;
    Info info{body_start + body.size(), INT64_MAX, INT64_MIN, {}};
    for (const Msg& m : chunk) {
      for (const Conn& c : conns) {
        if (c.id == m.conn && written.insert(c.id).second) connection_record(c, &data);
      }
      const uint32_t offset = static_cast<uint32_t>(data.size());
      AppendRecord(&data, {{"op", OpValue(Op::kMessageData)}, {"conn", U32Value(m.conn)},
                           {"time", Time(m.time_ns)}},
                   m.data);
      index[m.conn] += Time(m.time_ns) + U32Value(offset);
      ++info.counts[m.conn];
      info.start = std::min(info.start, m.time_ns);
      info.end = std::max(info.end, m.time_ns);
    }
    if (!options.open_last_chunk_compression.empty() && &chunk == &chunks.back()) {
      const std::string& compression = options.open_last_chunk_compression;
      AppendRecord(&body, {{"op", OpValue(Op::kChunk)}, {"compression", compression},
                           {"size", U32Value(0)}},
                   "");
      body += compression == "none" ? data : std::string("\x04\x22\x4d\x18\x64\x60\x85", 7);
      break;
    }
    const uint32_t size = options.declared_chunk_size != 0
                              ? options.declared_chunk_size
                              : static_cast<uint32_t>(data.size());
    AppendRecord(&body, {{"op", OpValue(Op::kChunk)}, {"compression", options.compression},
                         {"size", U32Value(size)}},
                 data);
    for (const auto& [conn, entries] : index) {
      uint32_t count = static_cast<uint32_t>(entries.size() / kIndexEntrySize);
      if (first_index) count += options.index_count_delta;
      first_index = false;
      AppendRecord(&body, {{"op", OpValue(Op::kIndexData)}, {"ver", U32Value(kIndexDataVersion)},
                           {"conn", U32Value(conn)}, {"count", U32Value(count)}},
                   entries);
    }
    infos.push_back(info);
  }
  const uint64_t index_pos = body_start + body.size();
  if (options.indexed) {
    for (const Conn& c : conns) connection_record(c, &body);
    for (const Info& info : infos) {
      std::string data;
      for (const auto& [conn, count] : info.counts) data += U32Value(conn) + U32Value(count);
      AppendRecord(&body, {{"op", OpValue(Op::kChunkInfo)},
                           {"ver", U32Value(options.chunk_info_version)},
                           {"chunk_pos", U64Value(info.pos)},
                           {"start_time", Time(info.start)},
                           {"end_time", Time(info.end)},
                           {"count", U32Value(static_cast<uint32_t>(info.counts.size()))}},
                   data);
    }
  }
  HeaderFields header{{"op", OpValue(Op::kBagHeader)},
                      {"index_pos", U64Value(options.indexed ? index_pos : 0)},
                      {"conn_count", U32Value(options.indexed ? conns.size() : 0)},
                      {"chunk_count", U32Value(options.indexed ? infos.size() : 0)}};
  if (!options.encryptor.empty()) header["encryptor"] = options.encryptor;
  const size_t header_size = BuildHeader(header).size();
  std::string bag(kVersionLine);
  AppendRecord(&bag, header, std::string(kBagHeaderPaddedSize - header_size, ' '));
  EXPECT_EQ(bag.size(), body_start);
  return bag + body;
}

class BagReaderTest : public ::testing::Test {
 protected:
  std::string Write(const std::string& bytes, const std::string& name = "test.bag") {
    const std::string path = tmp_.File(name);
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }
  testing::TempDir tmp_;
};

struct Seen {
  std::string topic;
  int64_t time_ns;
  std::string data;
};

Status ReadAll(BagReader* reader, std::vector<Seen>* seen, ReadOptions options = {}) {
  return reader->ReadMessages(options, [&](const MessageView& m) {
    seen->push_back({m.connection->topic, m.time_ns,
                     std::string(reinterpret_cast<const char*>(m.data), m.size)});
    return Status::Ok();
  });
}

const std::vector<Conn> kTwoImuConns = {{1, "/imu", "sensor_msgs/Imu"},
                                        {2, "/imu", "sensor_msgs/Imu"},
                                        {5, "points", "sensor_msgs/PointCloud2"}};

TEST_F(BagReaderTest, ConnectionsOfOneTopicAreMergedInTimeOrder) {
  const std::string path = Write(
      BuildBag(kTwoImuConns, {{{1, 1000, "a"}, {2, 2000, "b"}, {5, 2500, "p"}, {1, 3000, "c"}},
                              {{2, 4000, "d"}, {1, 5000, "e"}}}));
  BagReader reader;
  Status status = reader.Open(path);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(reader.TopicsOfType("sensor_msgs/Imu"), std::vector<std::string>{"/imu"});
  EXPECT_EQ(reader.MessageCount("/imu"), 5);
  EXPECT_EQ(reader.MessageCount("points"), 1);
  int64_t start = 0, end = 0;
  ASSERT_TRUE(reader.TimeRange(&start, &end));
  EXPECT_EQ(start, 1000);
  EXPECT_EQ(end, 5000);
  std::vector<Seen> seen;
  ReadOptions options;
  options.topics = {"/imu"};
  ASSERT_TRUE(ReadAll(&reader, &seen, options).ok());
  ASSERT_EQ(seen.size(), 5u);
  const std::string expected = "abcde";
  for (size_t i = 0; i < seen.size(); ++i) {
    EXPECT_EQ(seen[i].data, expected.substr(i, 1));
    EXPECT_EQ(seen[i].time_ns, 1000 * static_cast<int64_t>(i + 1));
  }
  // A window on record time, [2000, 4000).
  seen.clear();
  options.start_ns = 2000;
  options.end_ns = 4000;
  ASSERT_TRUE(ReadAll(&reader, &seen, options).ok());
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[0].data, "b");
  EXPECT_EQ(seen[1].data, "c");
  // An unknown topic is an error.
  options.topics = {"/nope"};
  status = ReadAll(&reader, &seen, options);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("no topic '/nope'"), std::string::npos);
}

TEST_F(BagReaderTest, TimeTiesFollowChunkPositionThenOffset) {
  // Equal record times: file order decides (chunk_pos, then offset).
  const std::string path = Write(
      BuildBag(kTwoImuConns, {{{2, 7000, "1"}, {1, 7000, "2"}}, {{1, 7000, "3"}, {2, 6000, "0"}}}));
  BagReader reader;
  ASSERT_TRUE(reader.Open(path).ok());
  std::vector<Seen> seen;
  ASSERT_TRUE(ReadAll(&reader, &seen).ok());
  ASSERT_EQ(seen.size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_EQ(seen[i].data, std::to_string(i));
}

TEST_F(BagReaderTest, OneChunkCacheReloadsChunksAndStaysCorrect) {
  // Ten chunks whose times interleave: reading in time order alternates chunks.
  std::vector<std::vector<Msg>> chunks(10);
  for (int k = 0; k < 10; ++k) {
    chunks[k] = {{1, 1000 + k, "a" + std::to_string(k)}, {1, 2000 + k, "b" + std::to_string(k)}};
  }
  const std::string path = Write(BuildBag(kTwoImuConns, chunks));
  BagReader reader;
  ASSERT_TRUE(reader.Open(path).ok());
  std::vector<Seen> seen;
  ReadOptions options;
  options.chunk_cache_size = 1;
  ASSERT_TRUE(ReadAll(&reader, &seen, options).ok());
  ASSERT_EQ(seen.size(), 20u);
  for (int k = 0; k < 10; ++k) {
    EXPECT_EQ(seen[k].data, "a" + std::to_string(k));
    EXPECT_EQ(seen[10 + k].data, "b" + std::to_string(k));
  }
  EXPECT_EQ(reader.stats().chunks_decompressed, 20u);  // every chunk loaded twice
}

// The same messages and the same stats whether chunks are loaded on demand
// or read ahead on the second thread, with and without evictions.
TEST_F(BagReaderTest, ReadAheadGivesTheSameMessagesAsLoadingOnDemand) {
  // Chunk k holds times 1000 + k and 2000 + k (reading in time order visits
  // every chunk twice) and chunk-local times 5000 + 10 k (visited once).
  std::vector<std::vector<Msg>> chunks(12);
  for (int k = 0; k < 12; ++k) {
    chunks[k] = {{1, 1000 + k, "a" + std::to_string(k)},
                 {5, 5000 + 10 * k, "p" + std::to_string(k)},
                 {2, 2000 + k, "b" + std::to_string(k)}};
  }
  const std::string path = Write(BuildBag(kTwoImuConns, chunks));
  for (size_t cache : {1, 3, 8}) {
    BagReader on_demand;
    ASSERT_TRUE(on_demand.Open(path).ok());
    std::vector<Seen> expected;
    ReadOptions options;
    options.chunk_cache_size = cache;
    ASSERT_TRUE(ReadAll(&on_demand, &expected, options).ok());
    ASSERT_EQ(expected.size(), 36u);
    for (size_t ahead : {1, 2, 5, 16}) {
      BagReader reader;
      ASSERT_TRUE(reader.Open(path).ok());
      std::vector<Seen> seen;
      options.read_ahead_chunks = ahead;
      ASSERT_TRUE(ReadAll(&reader, &seen, options).ok());
      ASSERT_EQ(seen.size(), expected.size()) << "cache " << cache << " ahead " << ahead;
      for (size_t i = 0; i < seen.size(); ++i) {
        EXPECT_EQ(seen[i].data, expected[i].data) << i;
        EXPECT_EQ(seen[i].time_ns, expected[i].time_ns) << i;
      }
      EXPECT_EQ(reader.stats().chunks_decompressed, on_demand.stats().chunks_decompressed);
    }
  }
}

// lz4 chunks as roslz4 writes them (BagWriter), several per bag: the read
// ahead decompresses and verifies them on its thread; a callback that stops
// early ends the read ahead cleanly.
TEST_F(BagReaderTest, ReadAheadOfLz4ChunksAndAnEarlyStop) {
  const std::string path = tmp_.File("lz4.bag");
  {
    BagWriter writer;
    ASSERT_TRUE(writer.Open(path, ChunkCompression::kLz4, 4096).ok());
    const uint32_t imu = writer.AddConnection("/imu", "sensor_msgs/Imu", "md5", "def");
    for (int i = 0; i < 2000; ++i) {
      ASSERT_TRUE(writer.Write(imu, 1000 + i, std::string(100, static_cast<char>('a' + i % 26)))
                      .ok());
    }
    ASSERT_TRUE(writer.Close().ok());
  }
  std::vector<Seen> expected, seen;
  BagReader on_demand, ahead;
  ASSERT_TRUE(on_demand.Open(path).ok());
  ASSERT_TRUE(ahead.Open(path).ok());
  ASSERT_TRUE(ReadAll(&on_demand, &expected).ok());
  ReadOptions options;
  options.read_ahead_chunks = 2;
  ASSERT_TRUE(ReadAll(&ahead, &seen, options).ok());
  ASSERT_EQ(seen.size(), 2000u);
  EXPECT_GT(ahead.stats().chunks_decompressed, 10u);
  for (size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i].data, expected[i].data) << i;
  int calls = 0;
  const Status stopped = ahead.ReadMessages(options, [&](const MessageView&) {
    return ++calls == 50 ? Status::Error("stop") : Status::Ok();
  });
  EXPECT_EQ(stopped.message(), "stop");
}

TEST_F(BagReaderTest, UnindexedBagIsScanned) {
  BagOptions options;
  options.indexed = false;
  const std::string path = Write(BuildBag(
      kTwoImuConns, {{{1, 1000, "a"}, {5, 1500, "p"}}, {{2, 500, "z"}, {1, 3000, "c"}}}, options));
  BagReader reader;
  Status status = reader.Open(path);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_FALSE(reader.indexed());
  EXPECT_EQ(reader.num_salvaged_messages(), 4);
  EXPECT_EQ(reader.salvage_note(), "");
  std::vector<Seen> seen;
  ASSERT_TRUE(ReadAll(&reader, &seen).ok());
  ASSERT_EQ(seen.size(), 4u);
  EXPECT_EQ(seen[0].data, "z");
  EXPECT_EQ(seen[1].data, "a");
  EXPECT_EQ(seen[2].topic, "points");
}

TEST_F(BagReaderTest, OpenChunksOfAnInterruptedRecording) {
  BagOptions options;
  options.indexed = false;
  options.open_last_chunk_compression = "none";
  const std::vector<std::vector<Msg>> chunks = {{{1, 1000, "a"}}, {{1, 2000, "b"}, {5, 2100, "p"}}};
  // Open uncompressed chunk: its records are read up to the end of the file,
  // an incomplete last record is left out.
  const std::string bag = BuildBag(kTwoImuConns, chunks, options);
  BagReader reader;
  ASSERT_TRUE(reader.Open(Write(bag, "a.bag")).ok());
  EXPECT_EQ(reader.num_salvaged_messages(), 3);
  EXPECT_EQ(reader.salvage_note(), "");
  BagReader cut;
  ASSERT_TRUE(cut.Open(Write(bag.substr(0, bag.size() - 2), "b.bag")).ok());
  EXPECT_EQ(cut.num_salvaged_messages(), 2);
  EXPECT_NE(cut.salvage_note().find("incomplete record"), std::string::npos) << cut.salvage_note();
  std::vector<Seen> seen;
  ASSERT_TRUE(ReadAll(&cut, &seen).ok());
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[1].data, "b");
  // Open lz4 chunk: nothing to recover, and the note says so.
  options.open_last_chunk_compression = "lz4";
  BagReader lz4;
  ASSERT_TRUE(lz4.Open(Write(BuildBag(kTwoImuConns, chunks, options), "c.bag")).ok());
  EXPECT_EQ(lz4.num_salvaged_messages(), 1);
  EXPECT_NE(lz4.salvage_note().find("open lz4 chunk"), std::string::npos) << lz4.salvage_note();
}

TEST_F(BagReaderTest, EncryptedBagIsRejected) {
  BagOptions options;
  options.encryptor = "rosbag/AesCbcEncryptor";
  const std::string path = Write(BuildBag(kTwoImuConns, {{{1, 1000, "a"}}}, options));
  BagReader reader;
  Status status = reader.Open(path);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("encrypted bag"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find(path), std::string::npos);
}

TEST_F(BagReaderTest, IndexInconsistenciesAreErrors) {
  {
    BagOptions options;
    options.index_count_delta = 1;
    const std::string path = Write(BuildBag(kTwoImuConns, {{{1, 1000, "a"}}}, options), "a.bag");
    BagReader reader;
    ASSERT_TRUE(reader.Open(path).ok());
    std::vector<Seen> seen;
    Status status = ReadAll(&reader, &seen);
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.message().find("index data with 2 entries"), std::string::npos)
        << status.message();
  }
  {
    BagOptions options;
    options.chunk_info_version = 2;
    const std::string path = Write(BuildBag(kTwoImuConns, {{{1, 1000, "a"}}}, options), "b.bag");
    BagReader reader;
    Status status = reader.Open(path);
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.message().find("chunk info version 2"), std::string::npos)
        << status.message();
  }
  {
    BagOptions options;
    options.compression = "zstd";
    const std::string path = Write(BuildBag(kTwoImuConns, {{{1, 1000, "a"}}}, options), "c.bag");
    BagReader reader;
    Status status = reader.Open(path);
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.message().find("unsupported chunk compression 'zstd'"), std::string::npos)
        << status.message();
  }
}

// Peak resident memory of this process so far, MB.
double PeakRssMb() {
  struct rusage usage {};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

// A chunk that declares 200 MB in a file of a few hundred bytes is an error,
// indexed or scanned, without the 200 MB being allocated (none, lz4: refused
// from the header; bz2, which can expand a million-fold, up to 1 GiB is
// allocated but only what the decompressor writes is touched).
TEST_F(BagReaderTest, ChunkSizeBeyondItsDataIsRefusedBeforeAllocating) {
  const std::map<std::string, std::string> expected = {
      {"none", "data bytes"}, {"lz4", "cannot decompress"}, {"bz2", "bz2 chunk"}};
  for (const auto& [compression, expected_text] : expected) {
    for (bool indexed : {true, false}) {
      SCOPED_TRACE(compression + (indexed ? " indexed" : " scanned"));
      BagOptions options;
      options.compression = compression;
      options.indexed = indexed;
      options.declared_chunk_size = 200000000;
      const std::string path = Write(BuildBag(kTwoImuConns, {{{1, 1000, "a"}}}, options));
      const double rss_before_mb = PeakRssMb();
      BagReader reader;
      const Status status = reader.Open(path);
      std::string message = status.message();
      if (status.ok()) {  // bz2 indexed: an error when read; scanned: the scan stops there
        EXPECT_TRUE(compression == "bz2" || !indexed);
        std::vector<Seen> seen;
        const Status read = ReadAll(&reader, &seen);
        message = read.ok() ? reader.salvage_note() : read.message();
        EXPECT_TRUE(seen.empty());
      }
      EXPECT_NE(message.find("200000000"), std::string::npos) << message;
      EXPECT_NE(message.find(expected_text), std::string::npos) << message;
      EXPECT_LT(PeakRssMb() - rss_before_mb, 100.0);
    }
  }
}

// Any prefix or any single corrupted byte gives a result or an error, never
// a crash or a read outside the buffers (run under TILTCAL_SANITIZE to check).
TEST_F(BagReaderTest, TruncationsAndByteFlipsNeverCrash) {
  for (bool indexed : {true, false}) {
    BagOptions options;
    options.indexed = indexed;
    const std::string bag = BuildBag(
        kTwoImuConns, {{{1, 1000, "aaaa"}, {5, 1500, "pp"}}, {{2, 2000, "bb"}, {1, 3000, "c"}}},
        options);
    const size_t body = kVersionLine.size() + 8 + kBagHeaderPaddedSize;
    // Fresh file names: rewriting one file in place makes ext4 flush it each time.
    int variant = 0;
    auto try_read = [&](const std::string& bytes) {
      const std::string path = Write(bytes, "v" + std::to_string(variant++) + ".bag");
      BagReader reader;
      std::vector<Seen> seen;
      const bool opened = reader.Open(path).ok();
      if (opened) {
        const Status on_demand = ReadAll(&reader, &seen);
        EXPECT_LE(seen.size(), 4u);
        // Reading ahead gives the same messages and the same error.
        BagReader ahead_reader;
        EXPECT_TRUE(ahead_reader.Open(path).ok());
        std::vector<Seen> ahead_seen;
        ReadOptions ahead;
        ahead.read_ahead_chunks = 2;
        const Status read_ahead = ReadAll(&ahead_reader, &ahead_seen, ahead);
        EXPECT_EQ(read_ahead.message(), on_demand.message());
        EXPECT_EQ(ahead_seen.size(), seen.size());
      }
      std::remove(path.c_str());
      return opened;
    };
    int opened = 0;
    for (size_t n = 0; n < bag.size(); n += (n < body ? 97 : 3)) opened += try_read(bag.substr(0, n));
    // Prefixes of an indexed bag lack the index (an error); unindexed ones are salvaged.
    EXPECT_EQ(opened > 0, !indexed);
    for (size_t i = body; i < bag.size(); ++i) {
      std::string bad = bag;
      bad[i] = static_cast<char>(bad[i] ^ 0xA5);
      (void)try_read(bad);
    }
  }
  // The unindexed bag cut in its second chunk keeps the first chunk's messages.
  BagOptions options;
  options.indexed = false;
  const std::string bag = BuildBag(kTwoImuConns, {{{1, 1000, "a"}}, {{1, 2000, "b"}}}, options);
  // The same bag with only the first chunk is a prefix of it.
  const size_t first_chunk_end = BuildBag(kTwoImuConns, {{{1, 1000, "a"}}}, options).size();
  ASSERT_EQ(bag.substr(0, first_chunk_end),
            BuildBag(kTwoImuConns, {{{1, 1000, "a"}}}, options));
  BagReader reader;
  ASSERT_TRUE(reader.Open(Write(bag.substr(0, first_chunk_end + 30))).ok());
  EXPECT_EQ(reader.num_salvaged_messages(), 1);
  EXPECT_NE(reader.salvage_note().find("incomplete record"), std::string::npos)
      << reader.salvage_note();
}

}  // namespace
}  // namespace tiltcal::ros1
