#ifndef TILTCAL_COMMON_IO_SCAN_ENCODER_H_
#define TILTCAL_COMMON_IO_SCAN_ENCODER_H_

#include <cstddef>
#include <cstdint>

#include <google/protobuf/io/coded_stream.h>

#include "tiltcal/proto/scan.pb.h"

namespace tiltcal {

// Writes a proto::Scan in protobuf's wire format, the same bytes as
// Scan::SerializeAsString() (fields in number order, proto3 defaults left
// out, packed columns with their byte length), without protobuf's generated
// code: the float columns are copied as they are (little-endian IEEE 754),
// the varint columns (`ring` uint32, `time_offset_ns` sint32) are sized with
// loops the compiler vectorises and encoded in blocks through a small
// buffer. A scan with unknown fields is left to protobuf (Supported()).
class ScanEncoder {
 public:
  // False when the scan holds something the encoder does not write (unknown
  // fields): serialize it with protobuf then.
  static bool Supported(const proto::Scan& scan);

  // The scan's serialized size in bytes (as ByteSizeLong()); remembers the
  // varint column sizes for the Write() of the same scan that follows.
  size_t ByteSize(const proto::Scan& scan);
  // Writes the scan; ByteSize(scan) must have been called on it, unchanged.
  void Write(const proto::Scan& scan, google::protobuf::io::CodedOutputStream* out) const;

  // Bytes of the varints of `values` (as uint32) / of their zigzag encodings.
  static size_t UInt32VarintBytes(const uint32_t* values, size_t n);
  static size_t SInt32VarintBytes(const int32_t* values, size_t n);

 private:
  size_t ring_bytes_ = 0;
  size_t time_bytes_ = 0;
};

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_SCAN_ENCODER_H_
