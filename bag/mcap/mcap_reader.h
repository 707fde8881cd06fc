#ifndef TILTCAL_BAG_MCAP_MCAP_READER_H_
#define TILTCAL_BAG_MCAP_MCAP_READER_H_

// Reader of MCAP files (format.h) without the MCAP library, for ROS 2
// recordings (message encoding "cdr", schemas "ros2msg") and ROS 1 ones
// ("ros1").
//
// Open() reads the summary when the file ends with a footer that points to
// one with chunk indexes: schemas and channels from it, and every chunk's
// message index records (log time and offset of each message), without
// decompressing a chunk. Otherwise (no summary, or a recording cut short
// with no footer) it scans the data section record by record,
// decompressing each chunk once to index its messages; a record that runs
// past the end of the file ends the scan, and everything before it is
// salvaged (indexed() false, salvage_note() says where it stopped).
// ReadMessages() then yields the selected messages in (log time, chunk
// position, offset) order, decompressing chunks on demand into a small LRU
// cache, emptied when it returns: memory is bounded by the cache plus 24
// bytes per message.
// The file is read with pread(); a chunk whose CRC or size does not match,
// an unknown compression, a record that does not parse are errors naming
// the file and the byte offset of the record.

#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bag/mcap/chunk_decompressor.h"
#include "bag/mcap/format.h"
#include "bag/message_reader.h"
#include "common/status.h"

namespace tiltcal::mcap {

class McapReader : public bag::MessageReader {
 public:
  McapReader();
  ~McapReader() override;
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  // Whether Open() may read the summary (kNever: the data section is
  // scanned even when a usable summary is there, the streaming read).
  enum class SummaryUse { kIfUsable, kNever };
  Status Open(const std::string& path, SummaryUse summary_use = SummaryUse::kIfUsable);

  // The order of ReadMessageRecords().
  enum class Order {
    kLogTime,  // (log time, file position), as ReadMessages()
    kFile,     // as the Message records lie in the file
  };
  // Calls `fn` for every selected message with its Message record as the
  // file holds it (channel, sequence, log and publish time, data), whatever
  // its channel's message encoding: bag::Message::encoding is kRos1 for
  // "ros1" channels and kCdr for every other. ReadMessages() is this in
  // log-time order, for cdr and ros1 channels only.
  Status ReadMessageRecords(
      const bag::MessageSelection& selection, Order order,
      const std::function<Status(const bag::Message&, const MessageRecord&)>& fn);


  // The profile of the Header record ("ros2", "ros1", ...).
  const std::string& profile() const { return profile_; }
  // True when Open() used the summary section.
  bool used_summary() const { return indexed_; }

  const std::string& path() const override { return path_; }
  uint64_t size_bytes() const override { return file_size_; }
  std::string format_name() const override { return "MCAP"; }
  bool indexed() const override { return indexed_; }
  // Only a recording cut short is salvaged; a complete file without a
  // summary is read whole by the scan.
  int64_t num_salvaged_messages() const override {
    return salvage_note_.empty() ? 0 : static_cast<int64_t>(entries_.size());
  }
  std::string salvage_note() const override { return salvage_note_; }
  uint64_t chunks_decompressed() const override { return chunks_decompressed_; }
  // Read from the compression field of each Chunk record.
  Status ChunkCompressions(std::map<std::string, int64_t>* compressions) const override;
  const std::vector<bag::TopicInfo>& topics() const override { return topics_; }
  bool TimeRange(int64_t* start_ns, int64_t* end_ns) const override;
  Status ReadMessages(const bag::MessageSelection& selection,
                      const std::function<Status(const bag::Message&)>& fn) override;

 private:
  static constexpr uint32_t kNoChunk = UINT32_MAX;
  // Where a message is: its log time, its chunk (kNoChunk: a record of the
  // data section itself) and the offset of its record in the uncompressed
  // chunk (or in the file).
  struct Entry {
    int64_t time_ns;
    uint64_t offset;
    uint32_t chunk;
    uint16_t channel;
  };
  struct Chunk {
    uint64_t offset;  // of the chunk record in the file
    uint64_t length;  // of the whole record
  };
  struct Channel {
    std::string topic;
    std::string message_encoding;
    uint16_t schema_id = 0;
  };
  struct CachedChunk {
    uint32_t chunk;
    std::vector<uint8_t> records;
  };

  Status Error(uint64_t offset, const std::string& what) const;
  Status ReadAt(uint64_t offset, uint64_t size, void* dst) const;
  // Reads the record at `offset`: opcode and content (into *content).
  Status ReadRecord(uint64_t offset, uint64_t end, uint8_t* opcode,
                    std::vector<uint8_t>* content) const;
  Status ReadHeader();
  // Reads the summary; *usable is false when there is none or it lacks the
  // chunk and message indexes.
  Status ReadSummary(bool* usable);
  Status IndexChunkFromSummary(const ChunkIndexRecord& index);
  Status ScanDataSection();
  // Indexes the schemas, channels and messages among the records in
  // [data, data + size) of chunk `chunk` (kNoChunk: the file at `base`).
  Status IndexRecords(const uint8_t* data, size_t size, uint32_t chunk, uint64_t base);
  Status AddSchemaOrChannel(uint8_t opcode, const uint8_t* content, size_t size,
                            uint64_t offset);
  void FinishTopics();
  // The decompressed records of chunk `chunk`, from the cache or the file.
  Status LoadChunk(uint32_t chunk, const std::vector<uint8_t>** records);
  Status DecompressChunkAt(uint64_t offset, uint64_t length, std::vector<uint8_t>* records);

  std::string path_;
  int fd_ = -1;
  uint64_t file_size_ = 0;
  std::string profile_;
  bool indexed_ = true;
  std::string salvage_note_;
  std::vector<std::string> schema_names_;  // by schema id; "" when absent
  std::vector<std::unique_ptr<Channel>> channels_;  // by channel id; null when absent
  std::vector<Chunk> chunks_;
  std::vector<Entry> entries_;
  std::vector<bag::TopicInfo> topics_;
  int64_t start_ns_ = INT64_MAX;
  int64_t end_ns_ = INT64_MIN;
  ChunkDecompressor decompressor_;
  std::list<CachedChunk> cache_;  // most recently used first
  size_t cache_size_ = 8;
  uint64_t chunks_decompressed_ = 0;
};

}  // namespace tiltcal::mcap

#endif  // TILTCAL_BAG_MCAP_MCAP_READER_H_
