#ifndef TILTCAL_COMMON_IO_RECORD_STREAM_H_
#define TILTCAL_COMMON_IO_RECORD_STREAM_H_

#include <cstdio>
#include <memory>
#include <string>

#include <google/protobuf/io/zero_copy_stream.h>
#include <google/protobuf/message.h>

#include "common/io/atomic_file.h"
#include "common/io/lz4_stream.h"
#include "common/status.h"
#include "tiltcal/proto/stream.pb.h"

namespace google::protobuf::io {
class CodedInputStream;
}  // namespace google::protobuf::io

namespace tiltcal {

// Record stream file layout (docs/design.md §4):
//   kStreamMagic (8 bytes) · varint-delimited StreamHeader · varint-delimited records
//   · end mark: varint 0 · varint-delimited StreamEnd
// optionally wrapped as a whole in one LZ4 frame (`lz4 -dc` gives the plain
// stream). Readers detect the LZ4 frame by its magic. Records are never
// empty: a zero length is the end mark, and a stream without it is truncated.
inline constexpr char kStreamMagic[8] = {'T', 'I', 'L', 'T', 'C', 'A', 'L', '1'};
inline constexpr uint32_t kStreamFormatVersion = 2;

// Writes a record stream atomically: nothing appears at `path` until Close()
// succeeds.
class RecordWriter {
 public:
  RecordWriter();
  ~RecordWriter();

  // `payload_type` is the full proto name of the records; `compress` wraps the
  // stream in an LZ4 frame.
  Status Open(const std::string& path, const std::string& payload_type,
              const proto::Provenance& provenance, bool compress);
  // The stream wrapped in one LZ4 frame built as `lz4_options` say, the
  // file written as `file_options` say.
  Status Open(const std::string& path, const std::string& payload_type,
              const proto::Provenance& provenance, const Lz4FrameOptions& lz4_options,
              const AtomicFileOptions& file_options = {});
  // An empty record (one that serialises to zero bytes) is an error: a zero
  // length marks the end of the stream.
  Status Write(const google::protobuf::Message& record);
  // Finish() and AtomicFile::Commit(): the stream appears at its path.
  Status Close();
  // Writes the end mark and completes the stream under its temporary name
  // (once; later calls do nothing), for CommitTogether({file(), ...}).
  Status Finish();
  AtomicFile* file();

  int64_t num_records() const { return num_records_; }

 private:
  Status OpenImpl(const std::string& path, const std::string& payload_type,
                  const proto::Provenance& provenance, const Lz4FrameOptions* lz4_options,
                  const AtomicFileOptions& file_options);
  class Impl;
  std::unique_ptr<Impl> impl_;
  int64_t num_records_ = 0;
};

// Reads a record stream written by RecordWriter, plain or LZ4-framed.
class RecordReader {
 public:
  RecordReader();
  ~RecordReader();

  // Opens `path` and reads its header. With a non-empty `expected_payload_type`
  // a file holding other records is an error naming both types.
  Status Open(const std::string& path, const std::string& expected_payload_type = "");

  // Reads the next record into `record`. At the end mark returns Ok with
  // *end = true (and so on every later call); a truncated or corrupt record,
  // a missing or wrong end mark, or data after it is an error naming the file
  // and the record index.
  Status Read(google::protobuf::Message* record, bool* end);

  const proto::StreamHeader& header() const { return header_; }
  const std::string& path() const { return path_; }
  int64_t num_records_read() const { return num_read_; }

 private:
  // After the zero length: the StreamEnd, its count, and the end of the file.
  Status ReadEndMark(google::protobuf::io::CodedInputStream* coded);
  Status RecordError(const std::string& what) const;

  class Impl;
  std::unique_ptr<Impl> impl_;
  proto::StreamHeader header_;
  std::string path_;
  int64_t num_read_ = 0;
  bool at_end_ = false;
};

// Reads every record of a stream of `Record` into `records`.
template <typename Record, typename Container>
Status ReadAllRecords(const std::string& path, Container* records,
                      proto::StreamHeader* header = nullptr) {
  RecordReader reader;
  TILTCAL_RETURN_IF_ERROR(reader.Open(path, Record::descriptor()->full_name()));
  if (header != nullptr) *header = reader.header();
  for (;;) {
    Record record;
    bool end = false;
    TILTCAL_RETURN_IF_ERROR(reader.Read(&record, &end));
    if (end) return Status::Ok();
    records->push_back(std::move(record));
  }
}

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_RECORD_STREAM_H_
