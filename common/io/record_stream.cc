#include "common/io/record_stream.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl.h>
#include <google/protobuf/util/delimited_message_util.h>

#include "common/io/input_file.h"
#include "common/io/lz4_stream.h"
#include "common/io/scan_encoder.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal {

namespace pbio = google::protobuf::io;
using google::protobuf::util::ParseDelimitedFromZeroCopyStream;
using google::protobuf::util::SerializeDelimitedToZeroCopyStream;

// ---------------------------------------------------------------- writer --

class RecordWriter::Impl {
 public:
  AtomicFile file;
  bool finished = false;
  // Record bytes since the last AtomicFile::WriteBehind(): it is called once
  // per MiB, not per record (an IMU stream has thousands of small records).
  size_t bytes_since_write_behind = 0;
  std::unique_ptr<Lz4FrameOutput> lz4;
  std::unique_ptr<pbio::CopyingOutputStreamAdaptor> lz4_adaptor;
  std::unique_ptr<pbio::FileOutputStream> plain;

  pbio::ZeroCopyOutputStream* stream() {
    return lz4_adaptor ? static_cast<pbio::ZeroCopyOutputStream*>(lz4_adaptor.get())
                       : plain.get();
  }
};

RecordWriter::RecordWriter() = default;
RecordWriter::~RecordWriter() = default;

Status RecordWriter::Open(const std::string& path, const std::string& payload_type,
                          const proto::Provenance& provenance, bool compress) {
  const Lz4FrameOptions lz4_options;
  return OpenImpl(path, payload_type, provenance, compress ? &lz4_options : nullptr, {});
}

Status RecordWriter::Open(const std::string& path, const std::string& payload_type,
                          const proto::Provenance& provenance,
                          const Lz4FrameOptions& lz4_options,
                          const AtomicFileOptions& file_options) {
  return OpenImpl(path, payload_type, provenance, &lz4_options, file_options);
}

Status RecordWriter::OpenImpl(const std::string& path, const std::string& payload_type,
                              const proto::Provenance& provenance,
                              const Lz4FrameOptions* lz4_options,
                              const AtomicFileOptions& file_options) {
  impl_ = std::make_unique<Impl>();
  num_records_ = 0;
  TILTCAL_RETURN_IF_ERROR(impl_->file.Open(path, file_options));
  if (lz4_options != nullptr) {
    impl_->lz4 = std::make_unique<Lz4FrameOutput>(impl_->file.file(), *lz4_options);
    // One LZ4 block (256 KiB) per Write(): liblz4 then compresses straight
    // from this buffer instead of first copying the input into its own.
    impl_->lz4_adaptor = std::make_unique<pbio::CopyingOutputStreamAdaptor>(
        impl_->lz4.get(), static_cast<int>(kLz4FrameBlockBytes));
  } else {
    std::fflush(impl_->file.file());
    impl_->plain = std::make_unique<pbio::FileOutputStream>(::fileno(impl_->file.file()));
  }
  {
    pbio::CodedOutputStream coded(impl_->stream());
    coded.WriteRaw(kStreamMagic, sizeof(kStreamMagic));
  }
  proto::StreamHeader header;
  header.set_payload_type(payload_type);
  header.set_format_version(kStreamFormatVersion);
  *header.mutable_provenance() = provenance;
  if (!SerializeDelimitedToZeroCopyStream(header, impl_->stream())) {
    return Status::Error(path + ": cannot write the stream header");
  }
  return Status::Ok();
}

Status RecordWriter::Write(const google::protobuf::Message& record) {
  // SerializeDelimitedToCodedStream, with the size computed once (it walks
  // every packed varint of a scan) and checked: a zero length is the end mark.
  // Scans, the bulk of the bytes, are written by ScanEncoder (same bytes).
  const auto* scan = dynamic_cast<const proto::Scan*>(&record);
  if (scan != nullptr && !ScanEncoder::Supported(*scan)) scan = nullptr;
  ScanEncoder encoder;
  const size_t size = scan != nullptr ? encoder.ByteSize(*scan) : record.ByteSizeLong();
  if (size == 0) {
    return Status::Error(impl_->file.path() + ": record " + std::to_string(num_records_) +
                         " is empty (a zero length marks the end of a record stream)");
  }
  bool ok = size <= static_cast<size_t>(std::numeric_limits<int>::max());
  if (ok) {
    pbio::CodedOutputStream coded(impl_->stream());
    coded.WriteVarint32(static_cast<uint32_t>(size));
    const int64_t start = coded.ByteCount();
    if (scan != nullptr) {
      encoder.Write(*scan, &coded);
    } else {
      uint8_t* direct = coded.GetDirectBufferForNBytesAndAdvance(static_cast<int>(size));
      if (direct != nullptr) {
        record.SerializeWithCachedSizesToArray(direct);
      } else {
        record.SerializeWithCachedSizes(&coded);
      }
    }
    ok = !coded.HadError() && coded.ByteCount() - start == static_cast<int64_t>(size);
  }
  if (!ok) {
    return Status::Error(impl_->file.path() + ": cannot write record " +
                         std::to_string(num_records_));
  }
  ++num_records_;
  impl_->bytes_since_write_behind += size;
  if (impl_->bytes_since_write_behind >= (size_t{1} << 20)) {
    impl_->file.WriteBehind();
    impl_->bytes_since_write_behind = 0;
  }
  return Status::Ok();
}

Status RecordWriter::Close() {
  TILTCAL_RETURN_IF_ERROR(Finish());
  return impl_->file.Commit();
}

Status RecordWriter::Finish() {
  if (impl_->finished) return Status::Ok();
  impl_->finished = true;
  const std::string& path = impl_->file.path();
  proto::StreamEnd end_mark;
  end_mark.set_num_records(num_records_);
  bool ok;
  {
    pbio::CodedOutputStream coded(impl_->stream());
    coded.WriteVarint32(0);
    ok = !coded.HadError();
  }
  ok = ok && SerializeDelimitedToZeroCopyStream(end_mark, impl_->stream());
  if (impl_->lz4_adaptor) {
    ok = ok && impl_->lz4_adaptor->Flush() && impl_->lz4->Close();
  } else {
    ok = ok && impl_->plain->Flush();
  }
  if (!ok) {
    const std::string message = path + ": cannot write output";
    impl_->file.Abandon();
    return Status::Error(message);
  }
  return impl_->file.Finish();
}

AtomicFile* RecordWriter::file() { return &impl_->file; }

// ---------------------------------------------------------------- reader --

class RecordReader::Impl {
 public:
  ~Impl() {
    stream_holder.reset();
    lz4.reset();
    if (file != nullptr) std::fclose(file);
  }
  std::FILE* file = nullptr;
  std::unique_ptr<Lz4FrameInput> lz4;
  std::unique_ptr<pbio::ZeroCopyInputStream> stream_holder;
  pbio::ZeroCopyInputStream* stream() { return stream_holder.get(); }
  // Error of the decompressor, if any: a decompression failure at a record
  // boundary would otherwise look like a clean end of the stream.
  std::string StreamError() const { return lz4 ? lz4->error() : std::string(); }
};

RecordReader::RecordReader() = default;
RecordReader::~RecordReader() = default;

Status RecordReader::Open(const std::string& path, const std::string& expected_payload_type) {
  impl_ = std::make_unique<Impl>();
  path_ = path;
  num_read_ = 0;
  at_end_ = false;
  // A FIFO or a device is refused before it is read (it could block or
  // never end).
  int fd = -1;
  uint64_t size = 0;
  TILTCAL_RETURN_IF_ERROR(OpenInputFile(path, &fd, &size));
  impl_->file = ::fdopen(fd, "rb");
  if (impl_->file == nullptr) {
    ::close(fd);
    return Status::Error(path + ": cannot open: " + std::strerror(errno));
  }
  if (::access(CommitManifestPath(path).c_str(), F_OK) == 0) {  // exists (never opened)
    return Status::Error(path + ": its writer was interrupted while committing it with other "
                         "outputs (" + CommitManifestPath(path) +
                         " exists); rerun the stage that wrote it");
  }
  unsigned char first[4] = {0, 0, 0, 0};
  const size_t got = std::fread(first, 1, sizeof(first), impl_->file);
  std::rewind(impl_->file);
  if (got == sizeof(first) && std::memcmp(first, kLz4FrameMagic, sizeof(first)) == 0) {
    impl_->lz4 = std::make_unique<Lz4FrameInput>(impl_->file);
    impl_->stream_holder =
        std::make_unique<pbio::CopyingInputStreamAdaptor>(impl_->lz4.get(), 1 << 16);
  } else {
    impl_->stream_holder = std::make_unique<pbio::FileInputStream>(::fileno(impl_->file));
  }
  char magic[sizeof(kStreamMagic)] = {};
  {
    pbio::CodedInputStream coded(impl_->stream());
    if (!coded.ReadRaw(magic, sizeof(magic)) ||
        std::memcmp(magic, kStreamMagic, sizeof(magic)) != 0) {
      const std::string detail = impl_->StreamError();
      return Status::Error(path + ": not a tiltcal record stream (bad magic" +
                           (detail.empty() ? "" : ", " + detail) + ")");
    }
  }
  bool clean_eof = false;
  if (!ParseDelimitedFromZeroCopyStream(&header_, impl_->stream(), &clean_eof)) {
    return Status::Error(path + ": cannot read the stream header");
  }
  if (header_.format_version() != kStreamFormatVersion) {
    return Status::Error(path + ": unsupported stream format version " +
                         std::to_string(header_.format_version()) + " (this build reads " +
                         std::to_string(kStreamFormatVersion) +
                         "); rerun the stage that wrote it with this build");
  }
  if (!expected_payload_type.empty() && header_.payload_type() != expected_payload_type) {
    return Status::Error(path + ": holds " + header_.payload_type() + " records, expected " +
                         expected_payload_type);
  }
  return Status::Ok();
}

namespace {

// ParseDelimitedFromCodedStream after its length: parses exactly `size`
// bytes of `coded` into `message`.
bool ParseSized(uint32_t size, google::protobuf::Message* message,
                pbio::CodedInputStream* coded) {
  if (size > static_cast<uint32_t>(std::numeric_limits<int>::max())) return false;
  const int start = coded->CurrentPosition();
  const pbio::CodedInputStream::Limit limit = coded->PushLimit(static_cast<int>(size));
  if (!message->MergePartialFromCodedStream(coded) || !coded->ConsumedEntireMessage() ||
      coded->CurrentPosition() - start != static_cast<int>(size)) {
    return false;
  }
  coded->PopLimit(limit);
  return true;
}

}  // namespace

Status RecordReader::Read(google::protobuf::Message* record, bool* end) {
  *end = false;
  if (at_end_) {
    *end = true;
    return Status::Ok();
  }
  record->Clear();  // parsing merges into what the message holds
  pbio::CodedInputStream coded(impl_->stream());
  uint32_t size = 0;
  if (!coded.ReadVarint32(&size)) {
    const std::string stream_error = impl_->StreamError();
    if (coded.CurrentPosition() == 0 && stream_error.empty()) {
      return RecordError("the stream ends without its end mark (truncated)");
    }
    return RecordError(stream_error.empty() ? "truncated or corrupt record" : stream_error);
  }
  if (size == 0) {
    TILTCAL_RETURN_IF_ERROR(ReadEndMark(&coded));
    at_end_ = true;
    *end = true;
    return Status::Ok();
  }
  if (!ParseSized(size, record, &coded)) {
    const std::string stream_error = impl_->StreamError();
    return RecordError(stream_error.empty() ? "truncated or corrupt record" : stream_error);
  }
  ++num_read_;
  return Status::Ok();
}

Status RecordReader::ReadEndMark(pbio::CodedInputStream* coded) {
  uint32_t size = 0;
  proto::StreamEnd end_mark;
  if (!coded->ReadVarint32(&size) || !ParseSized(size, &end_mark, coded)) {
    const std::string stream_error = impl_->StreamError();
    return RecordError(stream_error.empty() ? "truncated or corrupt end mark" : stream_error);
  }
  if (end_mark.num_records() != num_read_) {
    return RecordError("the end mark counts " + std::to_string(end_mark.num_records()) +
                       " records, the stream holds " + std::to_string(num_read_));
  }
  char extra = 0;
  if (coded->ReadRaw(&extra, 1)) return RecordError("data after the end mark");
  const std::string stream_error = impl_->StreamError();
  if (!stream_error.empty()) return RecordError(stream_error);
  return Status::Ok();
}

Status RecordReader::RecordError(const std::string& what) const {
  return Status::Error(path_ + ": record " + std::to_string(num_read_) + ": " + what);
}

}  // namespace tiltcal
