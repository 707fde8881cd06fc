#ifndef TILTCAL_STAGES_DECODE_ASYNC_RECORD_WRITER_H_
#define TILTCAL_STAGES_DECODE_ASYNC_RECORD_WRITER_H_

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <google/protobuf/message.h>

#include "common/io/record_stream.h"
#include "common/status.h"

namespace tiltcal {

// A RecordWriter whose serialization, LZ4 compression and file writes run on
// a background thread, so that they overlap with decoding. At most `depth`
// record objects exist; they are recycled (Acquire -> fill -> Submit), so
// memory stays bounded and columns keep their capacity between records.
// The output appears only when Close() succeeds (RecordWriter is atomic).
class AsyncRecordWriter {
 public:
  AsyncRecordWriter(const google::protobuf::Message& prototype, size_t depth);
  ~AsyncRecordWriter();
  AsyncRecordWriter(const AsyncRecordWriter&) = delete;
  AsyncRecordWriter& operator=(const AsyncRecordWriter&) = delete;

  // The stream in one LZ4 frame built as `lz4_options` say, the file written
  // as `file_options` say.
  Status Open(const std::string& path, const std::string& payload_type,
              const proto::Provenance& provenance, const Lz4FrameOptions& lz4_options,
              const AtomicFileOptions& file_options);

  // A record object to fill; it holds the values of an earlier record (the
  // caller overwrites every field it uses). Blocks while all are in flight.
  google::protobuf::Message* Acquire();
  // Gives back a record from Acquire() without writing it.
  void Release(google::protobuf::Message* record);
  // Queues a record from Acquire() for writing. Returns the error of an
  // earlier failed write, if any.
  Status Submit(google::protobuf::Message* record);
  // Writes what is queued and closes the stream.
  Status Close();
  // Writes every submitted record and completes the file under its
  // temporary name, for CommitTogether({file(), ...}).
  Status Finish();
  AtomicFile* file() { return writer_.file(); }

 private:
  void Work();
  void Stop();

  RecordWriter writer_;
  std::vector<std::unique_ptr<google::protobuf::Message>> storage_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<google::protobuf::Message*> free_;
  std::deque<google::protobuf::Message*> queue_;
  bool stopping_ = false;
  bool busy_ = false;
  Status error_;
  std::thread thread_;
};

}  // namespace tiltcal

#endif  // TILTCAL_STAGES_DECODE_ASYNC_RECORD_WRITER_H_
