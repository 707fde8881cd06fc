#include "stages/decode/async_record_writer.h"

#include <new>

namespace tiltcal {

AsyncRecordWriter::AsyncRecordWriter(const google::protobuf::Message& prototype,
                                     size_t depth) {
  for (size_t i = 0; i < std::max<size_t>(depth, 1); ++i) {
    storage_.emplace_back(prototype.New());
    free_.push_back(storage_.back().get());
  }
}

AsyncRecordWriter::~AsyncRecordWriter() { Stop(); }

void AsyncRecordWriter::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

Status AsyncRecordWriter::Open(const std::string& path, const std::string& payload_type,
                               const proto::Provenance& provenance,
                               const Lz4FrameOptions& lz4_options,
                               const AtomicFileOptions& file_options) {
  TILTCAL_RETURN_IF_ERROR(
      writer_.Open(path, payload_type, provenance, lz4_options, file_options));
  thread_ = std::thread([this] { Work(); });
  return Status::Ok();
}

void AsyncRecordWriter::Work() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping and drained
    google::protobuf::Message* record = queue_.front();
    queue_.pop_front();
    busy_ = true;
    const bool failed = !error_.ok() || stopping_;  // stopping before Close(): an error path
    lock.unlock();
    Status status;
    try {  // an exception would end the process from this thread
      if (!failed) status = writer_.Write(*record);
    } catch (const std::bad_alloc&) {
      status = Status::Error("out of memory writing a scan");
    }
    lock.lock();
    busy_ = false;
    if (!status.ok() && error_.ok()) error_ = status;
    free_.push_back(record);
    changed_.notify_all();
  }
}

google::protobuf::Message* AsyncRecordWriter::Acquire() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return !free_.empty(); });
  google::protobuf::Message* record = free_.back();
  free_.pop_back();
  return record;
}

void AsyncRecordWriter::Release(google::protobuf::Message* record) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    free_.push_back(record);
  }
  changed_.notify_all();
}

Status AsyncRecordWriter::Submit(google::protobuf::Message* record) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(record);
    if (!error_.ok()) return error_;
  }
  changed_.notify_all();
  return Status::Ok();
}

Status AsyncRecordWriter::Close() {
  TILTCAL_RETURN_IF_ERROR(Finish());
  return writer_.Close();
}

Status AsyncRecordWriter::Finish() {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return queue_.empty() && !busy_; });
  }
  Stop();
  TILTCAL_RETURN_IF_ERROR(error_);
  return writer_.Finish();
}

}  // namespace tiltcal
