#ifndef TILTCAL_BAG_MCAP_MCAP_READER_H_
#define TILTCAL_BAG_MCAP_MCAP_READER_H_

// Reader of MCAP files (format.h) without the MCAP library, for ROS 2
// recordings (message encoding "cdr", schemas "ros2msg") and ROS 1 ones
// ("ros1").
//
// Open() reads the summary when the file ends with a footer that points to
// one with chunk indexes: schemas and channels from it, and every chunk's
// message index records (log time and offset of each message), without
// decompressing a chunk. It then walks the data section record by record
// (9 bytes read per record): a chunk the summary omits, and messages outside
// chunks, are indexed from the data section, with a warning that the
// summary disagrees (the chunks win). Without a usable summary the walk
// decompresses each chunk once to index its messages.
//
// A file that ends with Footer and magic is complete, and its data section
// ends at a known byte (summary_start, else the Footer): a record that runs
// past it, a DataEnd elsewhere, or an opcode that cannot start a record
// (0, Header, Footer) is a damaged record. A Chunk whose own fields give a
// length from which the records after it chain onto the end is read with
// that length (its length alone was damaged). Otherwise the walk resumes at the
// first byte after it from which the records chain exactly onto the end of
// the data section (when the damage shows only at the misaligned record
// after a Message or Chunk, that record's own length is the damaged one: it
// and what it gave are dropped and the search starts inside it), with a
// warning naming the damaged record, the bytes skipped and the messages
// dropped (warnings()). Messages whose Channel record was lost with a
// damaged record have no topic: they are counted in a warning and left out.
// A recording cut short (no Footer and magic at the
// end) is salvaged up to the record that runs past the end of the file
// (indexed() false, salvage_note() says where it stopped).
//
// ReadMessages() then yields the selected messages in (log time, chunk
// position, offset) order, decompressing chunks on demand into a small LRU
// cache (at most 8 chunks, and at most max_chunk_bytes in all beyond the
// chunk in use), emptied when it returns: memory is bounded by the cache
// plus 24 bytes per message. A chunk that declares more than max_chunk_bytes
// decompressed is an error before anything is allocated.
// The file is read with pread(); a chunk whose CRC or size does not match,
// an unknown compression, a record that does not parse are errors naming
// the file and the byte offset of the record.

#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <string>
#include <unordered_set>
#include <vector>

#include "bag/mcap/chunk_decompressor.h"
#include "bag/mcap/format.h"
#include "bag/message_reader.h"
#include "common/status.h"

namespace tiltcal::mcap {

class McapReader : public bag::MessageReader {
 public:
  explicit McapReader(uint64_t max_chunk_bytes = bag::kDefaultMaxChunkBytes);
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
  std::vector<std::string> warnings() const override { return warnings_; }
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
    uint64_t offset;             // of the chunk record in the file
    uint64_t length;             // of the whole record
    uint64_t uncompressed_size;  // as declared (the cache's budget)
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
  // Reads the Footer: complete_, summary_start_, data_end_.
  Status ReadFooter();
  // Reads the summary; *usable is false when there is none or it lacks the
  // chunk and message indexes.
  Status ReadSummary(bool* usable);
  Status IndexChunkFromSummary(const ChunkIndexRecord& index);
  // Walks the data section (see the top of this file); chunks at the
  // offsets in chunks_ on entry (from the summary) are not read again.
  // Its steps are in data_section_walk.cc.
  Status WalkDataSection();
  struct WalkedRecord;
  struct Walk;
  // The prefix of the record at `offset`, and whether and why it is
  // damaged; *end when the data section (or a recording cut short) ends
  // there.
  Status ReadWalkedPrefix(uint64_t offset, WalkedRecord* record, bool* end);
  // A damaged Chunk whose own fields give a length from which the records
  // after it chain onto the end: that length, and not damaged.
  Status MendChunkLength(WalkedRecord* record);
  // Reads and indexes a Chunk the summary does not list, or a Schema,
  // Channel or Message record; sets record->damage when it does not parse.
  Status IndexWalkedRecord(WalkedRecord* record, Walk* walk);
  // When the damaged `record` is no record at all and follows a Chunk whose
  // own fields give a shorter length: that chunk's length is mended, and
  // *offset set after it (*mended).
  Status MendLastChunkLength(const WalkedRecord& record, Walk* walk, bool* mended,
                             uint64_t* offset);
  // Drops the damaged record (or the one before it whose length led to no
  // record) and what it gave, warns, and sets *offset where the records
  // chain onto the end again.
  Status SkipDamagedRecord(const WalkedRecord& record, Walk* walk, uint64_t* offset);
  // Leaves out the messages of channels no Channel record defines.
  void DropMessagesWithoutChannel();
  // The warnings of damaged records and of chunks the summary omits.
  void WarnAboutWalk(const Walk& walk);
  // The first offset in [from, data_end_) from which the records chain
  // exactly onto data_end_, outside the chunks listed by the summary;
  // data_end_ when there is none.
  Status FindResumeOffset(uint64_t from, size_t summary_chunks, uint64_t* resume);
  // The length of the Chunk record at `offset` by its own fields (header
  // and records_size) when the records after it chain from there onto
  // data_end_; 0 otherwise.
  Status ChunkLengthByItsFields(uint64_t offset, uint64_t* length);
  // The warning for a Chunk read with the length of its fields.
  std::string DamagedChunkLength(uint64_t offset, uint64_t declared, uint64_t by_fields) const;
  // True when the records from `offset` chain exactly onto data_end_.
  Status ChainsToDataEnd(uint64_t offset, bool* chains);
  Status IndexRecords(const uint8_t* data, size_t size, uint32_t chunk, uint64_t base);
  Status AddSchemaOrChannel(uint8_t opcode, const uint8_t* content, size_t size,
                            uint64_t offset);
  void FinishTopics();
  // The decompressed records of chunk `chunk`, from the cache or the file.
  Status LoadChunk(uint32_t chunk, const std::vector<uint8_t>** records);
  // Makes room in the cache for a chunk of `bytes` and puts a (reused)
  // buffer for it at the front; the cache's budget is max_chunk_bytes_.
  std::vector<uint8_t>* CacheSlot(uint32_t chunk, uint64_t bytes);
  Status DecompressChunkAt(uint64_t offset, uint64_t length, std::vector<uint8_t>* records);
  // Whether `channel` (null: not defined) is one of the selected topics.
  static bool ChannelSelected(const Channel* channel, const bag::MessageSelection& selection);
  // The entries of the selected channels inside the time window, in `order`.
  std::vector<const Entry*> SelectedEntries(const bag::MessageSelection& selection,
                                            Order order) const;
  // The Message record of entry `e` (read into *record when it lies outside
  // a chunk), checked against the entry; *where is the byte offset of its
  // chunk or record.
  Status ReadMessageRecord(const Entry& e, std::vector<uint8_t>* record,
                           MessageRecord* message, uint64_t* where);

  std::string path_;
  int fd_ = -1;
  uint64_t file_size_ = 0;
  std::string profile_;
  bool indexed_ = true;
  std::string salvage_note_;
  std::vector<std::string> warnings_;
  bool complete_ = false;         // the file ends with Footer and magic
  uint64_t summary_start_ = 0;    // 0: no summary
  uint64_t data_end_ = 0;         // the end of the data section (complete_), else the file's
  uint64_t header_end_ = 0;       // the first record after the Header
  std::unordered_set<uint64_t> dead_offsets_;  // known not to chain onto data_end_
  std::vector<std::string> schema_names_;  // by schema id; "" when absent
  std::vector<std::unique_ptr<Channel>> channels_;  // by channel id; null when absent
  std::vector<Chunk> chunks_;
  std::vector<Entry> entries_;
  std::vector<bag::TopicInfo> topics_;
  int64_t start_ns_ = INT64_MAX;
  int64_t end_ns_ = INT64_MIN;
  uint64_t max_chunk_bytes_;
  ChunkDecompressor decompressor_;
  std::list<CachedChunk> cache_;  // most recently used first
  size_t cache_size_ = 8;
  uint64_t cached_bytes_ = 0;
  uint64_t chunks_decompressed_ = 0;
};

}  // namespace tiltcal::mcap

#endif  // TILTCAL_BAG_MCAP_MCAP_READER_H_
