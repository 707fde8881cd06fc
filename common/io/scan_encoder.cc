#include "common/io/scan_encoder.h"

#include <algorithm>
#include <cstring>

namespace tiltcal {

namespace {

namespace wire = google::protobuf::io;

// Wire tags: field number << 3 | wire type (0 varint, 2 length-delimited).
constexpr uint32_t Tag(uint32_t field, uint32_t type) { return field << 3 | type; }

// Bytes of the varint of `v` minus 1: (v >= 2^7) + (v >= 2^14) + (v >= 2^21)
// + (v >= 2^28).
inline uint32_t ExtraBytes(uint32_t v) {
  return static_cast<uint32_t>(v >= (1u << 7)) + static_cast<uint32_t>(v >= (1u << 14)) +
         static_cast<uint32_t>(v >= (1u << 21)) + static_cast<uint32_t>(v >= (1u << 28));
}

inline uint32_t ZigZag(int32_t v) {
  return (static_cast<uint32_t>(v) << 1) ^ static_cast<uint32_t>(v >> 31);
}

// Varints of block values at most this many per WriteRaw (5 bytes each at most).
constexpr size_t kBlockValues = 2048;

// Encodes values[0, n) (already zigzagged when signed) as varints into `out`
// (room for 5 * n + 3 bytes); returns the end. Values below 2^28 take one
// 4-byte store: the 7-bit groups spread to bytes, continuation bits set on
// all but the last byte of the varint.
inline uint32_t Spread(uint32_t v) {
  return (v & 0x7Fu) | ((v << 1) & 0x7F00u) | ((v << 2) & 0x7F0000u) | ((v << 3) & 0x7F000000u);
}

inline uint8_t* EncodeVarint(uint32_t v, uint8_t* out) {
  if (v < (1u << 28)) {
    const uint32_t extra = ExtraBytes(v);  // 0..3
    const uint32_t word = Spread(v) | (0x00808080u >> (8 * (3 - extra)));
    std::memcpy(out, &word, 4);  // little-endian: first byte first
    return out + extra + 1;
  }
  while (v >= 0x80) {
    *out++ = static_cast<uint8_t>(v | 0x80);
    v >>= 7;
  }
  *out++ = static_cast<uint8_t>(v);
  return out;
}

// Values per run of the fixed-width path of EncodeVarints.
constexpr size_t kRunValues = 8;

inline uint8_t* EncodeVarints(const uint32_t* values, size_t n, uint8_t* out) {
  size_t i = 0;
  while (i + kRunValues <= n) {
    // A run whose values all take 4 bytes (2^21 <= v < 2^28: a Velodyne
    // scan's zigzagged time offsets beyond 1 ms) has fixed byte positions,
    // so its loop vectorises; any other run is encoded value by value.
    bool four_bytes = true;
    for (size_t k = 0; k < kRunValues; ++k) {
      four_bytes &= values[i + k] - (1u << 21) < (1u << 28) - (1u << 21);
    }
    if (four_bytes) {
      for (size_t k = 0; k < kRunValues; ++k) {
        const uint32_t word = Spread(values[i + k]) | 0x00808080u;
        std::memcpy(out + 4 * k, &word, 4);
      }
      out += 4 * kRunValues;
    } else {
      for (size_t k = 0; k < kRunValues; ++k) out = EncodeVarint(values[i + k], out);
    }
    i += kRunValues;
  }
  for (; i < n; ++i) out = EncodeVarint(values[i], out);
  return out;
}

// Bytes of the varints of to_uint(values[i]), i < n. The per-block sums of
// at most 4 extra bytes per value stay in uint32 and vectorise.
template <typename T, typename ToUInt>
size_t VarintBytes(const T* values, size_t n, ToUInt to_uint) {
  constexpr size_t kSumBlock = size_t{1} << 20;
  size_t total = n;
  for (size_t begin = 0; begin < n; begin += kSumBlock) {
    const size_t end = std::min(n, begin + kSumBlock);
    uint32_t extra = 0;
    for (size_t i = begin; i < end; ++i) extra += ExtraBytes(to_uint(values[i]));
    total += extra;
  }
  return total;
}

// Packed varint field `field` of to_uint(values[i]), i < n, whose payload is
// `payload_bytes` (VarintBytes); nothing when empty. A payload of n bytes
// means every value is below 2^7: one byte each.
template <typename T, typename ToUInt>
void WritePackedVarints(uint32_t field, size_t payload_bytes, const T* values, size_t n,
                        ToUInt to_uint, wire::CodedOutputStream* out) {
  if (payload_bytes == 0) return;
  out->WriteTag(Tag(field, 2));
  out->WriteVarint32(static_cast<uint32_t>(payload_bytes));
  uint32_t block[kBlockValues];
  uint8_t bytes[kBlockValues * 5 + 3];
  for (size_t begin = 0; begin < n; begin += kBlockValues) {
    const size_t count = std::min(kBlockValues, n - begin);
    uint8_t* end;
    if (payload_bytes == n) {
      for (size_t i = 0; i < count; ++i) bytes[i] = static_cast<uint8_t>(to_uint(values[begin + i]));
      end = bytes + count;
    } else {
      for (size_t i = 0; i < count; ++i) block[i] = to_uint(values[begin + i]);
      end = EncodeVarints(block, count, bytes);
    }
    out->WriteRaw(bytes, static_cast<int>(end - bytes));
  }
}

void WritePackedFloats(uint32_t field, const google::protobuf::RepeatedField<float>& values,
                       wire::CodedOutputStream* out) {
  if (values.empty()) return;
  static_assert(sizeof(float) == 4, "IEEE 754 single");
  out->WriteTag(Tag(field, 2));
  out->WriteVarint32(static_cast<uint32_t>(values.size()) * 4);
  out->WriteRaw(values.data(), values.size() * 4);
}

void WriteUInt32Field(uint32_t field, uint32_t value, wire::CodedOutputStream* out) {
  if (value == 0) return;
  out->WriteTag(Tag(field, 0));
  out->WriteVarint32(value);
}

void WriteInt64Field(uint32_t field, int64_t value, wire::CodedOutputStream* out) {
  if (value == 0) return;
  out->WriteTag(Tag(field, 0));
  out->WriteVarint64(static_cast<uint64_t>(value));
}

size_t UInt32FieldBytes(uint32_t value) {
  return value == 0 ? 0 : 1 + wire::CodedOutputStream::VarintSize32(value);
}

size_t Int64FieldBytes(int64_t value) {
  return value == 0 ? 0 : 1 + wire::CodedOutputStream::VarintSize64(static_cast<uint64_t>(value));
}

size_t PackedBytes(size_t payload) {
  return payload == 0 ? 0
                      : 1 + wire::CodedOutputStream::VarintSize32(static_cast<uint32_t>(payload)) +
                            payload;
}

}  // namespace

bool ScanEncoder::Supported(const proto::Scan& scan) {
  return !scan.GetReflection()->GetUnknownFields(scan).field_count();
}

size_t ScanEncoder::UInt32VarintBytes(const uint32_t* values, size_t n) {
  return VarintBytes(values, n, [](uint32_t v) { return v; });
}

size_t ScanEncoder::SInt32VarintBytes(const int32_t* values, size_t n) {
  return VarintBytes(values, n, [](int32_t v) { return ZigZag(v); });
}

size_t ScanEncoder::ByteSize(const proto::Scan& scan) {
  ring_bytes_ = UInt32VarintBytes(scan.ring().data(), scan.ring_size());
  time_bytes_ = SInt32VarintBytes(scan.time_offset_ns().data(), scan.time_offset_ns_size());
  size_t total = UInt32FieldBytes(scan.index()) + Int64FieldBytes(scan.stamp_ns()) +
                 Int64FieldBytes(scan.record_stamp_ns());
  if (!scan.frame_id().empty()) {
    total += 1 + wire::CodedOutputStream::VarintSize32(
                     static_cast<uint32_t>(scan.frame_id().size())) +
             scan.frame_id().size();
  }
  total += PackedBytes(4 * static_cast<size_t>(scan.x_size())) +
           PackedBytes(4 * static_cast<size_t>(scan.y_size())) +
           PackedBytes(4 * static_cast<size_t>(scan.z_size())) +
           PackedBytes(4 * static_cast<size_t>(scan.intensity_size())) + PackedBytes(ring_bytes_) +
           PackedBytes(time_bytes_);
  if (scan.time_source() != 0) {
    total += 1 + wire::CodedOutputStream::VarintSize32SignExtended(scan.time_source());
  }
  total += UInt32FieldBytes(scan.num_dropped_invalid()) +
           UInt32FieldBytes(scan.num_dropped_zero_range()) + (scan.deskewed() ? 2 : 0) +
           UInt32FieldBytes(scan.num_dropped_noise_tag());
  return total;
}

void ScanEncoder::Write(const proto::Scan& scan, wire::CodedOutputStream* out) const {
  WriteUInt32Field(1, scan.index(), out);
  WriteInt64Field(2, scan.stamp_ns(), out);
  WriteInt64Field(3, scan.record_stamp_ns(), out);
  if (!scan.frame_id().empty()) {
    out->WriteTag(Tag(4, 2));
    out->WriteVarint32(static_cast<uint32_t>(scan.frame_id().size()));
    out->WriteString(scan.frame_id());
  }
  WritePackedFloats(5, scan.x(), out);
  WritePackedFloats(6, scan.y(), out);
  WritePackedFloats(7, scan.z(), out);
  WritePackedFloats(8, scan.intensity(), out);
  WritePackedVarints(9, ring_bytes_, scan.ring().data(), static_cast<size_t>(scan.ring_size()),
                     [](uint32_t v) { return v; }, out);
  WritePackedVarints(10, time_bytes_, scan.time_offset_ns().data(),
                     static_cast<size_t>(scan.time_offset_ns_size()),
                     [](int32_t v) { return ZigZag(v); }, out);
  if (scan.time_source() != 0) {
    out->WriteTag(Tag(11, 0));
    out->WriteVarint32SignExtended(scan.time_source());
  }
  WriteUInt32Field(12, scan.num_dropped_invalid(), out);
  WriteUInt32Field(13, scan.num_dropped_zero_range(), out);
  if (scan.deskewed()) {
    out->WriteTag(Tag(14, 0));
    out->WriteVarint32(1);
  }
  WriteUInt32Field(15, scan.num_dropped_noise_tag(), out);
}

}  // namespace tiltcal
