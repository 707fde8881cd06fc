#include "common/io/scan_encoder.h"

#include <cstdint>
#include <limits>
#include <random>
#include <string>

#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <google/protobuf/wire_format_lite.h>
#include <gtest/gtest.h>

#include "tiltcal/proto/scan.pb.h"

namespace tiltcal {
namespace {

// The encoder's bytes, written through a CodedOutputStream with a small
// buffer size so that columns cross buffer boundaries.
std::string Encode(const proto::Scan& scan) {
  std::string bytes;
  ScanEncoder encoder;
  const size_t size = encoder.ByteSize(scan);
  {
    google::protobuf::io::StringOutputStream string_stream(&bytes);
    google::protobuf::io::CodedOutputStream coded(&string_stream);
    encoder.Write(scan, &coded);
    EXPECT_FALSE(coded.HadError());
  }
  EXPECT_EQ(size, bytes.size());
  EXPECT_EQ(size, scan.ByteSizeLong());
  return bytes;
}

void ExpectSameBytes(const proto::Scan& scan, const std::string& what) {
  ASSERT_TRUE(ScanEncoder::Supported(scan)) << what;
  const std::string expected = scan.SerializeAsString();
  const std::string actual = Encode(scan);
  ASSERT_EQ(actual.size(), expected.size()) << what;
  EXPECT_TRUE(actual == expected) << what;
}

// Values on both sides of every varint length boundary, signed and unsigned.
std::vector<uint32_t> BoundaryUnsigned() {
  std::vector<uint32_t> values = {0, 1, std::numeric_limits<uint32_t>::max()};
  for (int bits = 7; bits <= 28; bits += 7) {
    values.push_back((1u << bits) - 1);
    values.push_back(1u << bits);
    values.push_back((1u << bits) + 1);
  }
  values.push_back((1u << 31) - 1);
  values.push_back(1u << 31);
  return values;
}

std::vector<int32_t> BoundarySigned() {
  std::vector<int32_t> values = {0, 1, -1, std::numeric_limits<int32_t>::min(),
                                 std::numeric_limits<int32_t>::max()};
  for (int bits = 6; bits <= 27; bits += 7) {
    for (const int32_t v : {(1 << bits) - 1, 1 << bits, (1 << bits) + 1}) {
      values.push_back(v);
      values.push_back(-v);
    }
  }
  values.push_back(-(1 << 30));
  values.push_back(1 << 30);
  return values;
}

TEST(ScanEncoder, EmptyAndDefaultScans) {
  proto::Scan scan;
  ExpectSameBytes(scan, "empty");
  scan.set_index(0);
  scan.set_frame_id("");
  ExpectSameBytes(scan, "defaults set explicitly");
  scan.set_deskewed(true);
  ExpectSameBytes(scan, "only deskewed");
}

TEST(ScanEncoder, EveryScalarFieldAndExtremeValues) {
  proto::Scan scan;
  scan.set_index(std::numeric_limits<uint32_t>::max());
  scan.set_stamp_ns(std::numeric_limits<int64_t>::min());
  scan.set_record_stamp_ns(-1);
  scan.set_frame_id(std::string(200, 'f'));  // length takes two varint bytes
  scan.set_time_source(proto::POINT_TIME_LIVOX_CUSTOM_MSG);
  scan.set_num_dropped_invalid(127);
  scan.set_num_dropped_zero_range(128);
  scan.set_deskewed(true);
  scan.set_num_dropped_noise_tag(1u << 28);
  ExpectSameBytes(scan, "scalars");
  scan.set_stamp_ns(std::numeric_limits<int64_t>::max());
  scan.set_time_source(static_cast<proto::PointTimeSource>(-3));  // open enum: 10 bytes
  ExpectSameBytes(scan, "negative enum");
}

TEST(ScanEncoder, VarintBoundariesInTheColumns) {
  proto::Scan scan;
  for (const uint32_t v : BoundaryUnsigned()) scan.add_ring(v);
  for (const int32_t v : BoundarySigned()) scan.add_time_offset_ns(v);
  ExpectSameBytes(scan, "boundaries");
}

// Runs of values that all take 4 bytes (the encoder's fixed-width path),
// each with one value of another length, or on a length boundary, at every
// position of a run, and columns that end inside a run.
TEST(ScanEncoder, FourByteRunsWithOneOtherValueAtEveryPosition) {
  const std::vector<uint32_t> others = {0,           127,         (1u << 21) - 1, 1u << 21,
                                        (1u << 28) - 1, 1u << 28, 0xFFFFFFFFu};
  for (const uint32_t other : others) {
    for (int position = 0; position < 16; ++position) {
      proto::Scan scan;
      for (int i = 0; i < 16 + position; ++i) {
        const uint32_t v = i == position ? other : (1u << 21) + 12345u * static_cast<uint32_t>(i);
        scan.add_ring(v);
        // Zigzag of t is 2|t| or 2|t| - 1: these times give the same varints.
        scan.add_time_offset_ns(static_cast<int32_t>(v % 2 ? -static_cast<int64_t>(v / 2) - 1
                                                           : static_cast<int64_t>(v / 2)));
      }
      ExpectSameBytes(scan, "other " + std::to_string(other) + " at " + std::to_string(position));
    }
  }
}

TEST(ScanEncoder, ColumnsOfDifferentLengthsAndEmptyColumns) {
  proto::Scan scan;
  scan.add_x(1.5f);
  scan.add_z(-0.0f);
  scan.add_z(std::numeric_limits<float>::quiet_NaN());
  scan.add_intensity(std::numeric_limits<float>::infinity());
  ExpectSameBytes(scan, "no ring, no time");
  scan.add_time_offset_ns(0);  // a column of zeros is still written
  ExpectSameBytes(scan, "time of zero");
  scan.add_ring(0);
  ExpectSameBytes(scan, "ring of zero");
}

TEST(ScanEncoder, RandomScansOfManySizes) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> coordinate(-100.0f, 100.0f);
  // Sizes around the encoder's 2048-value blocks and larger than a buffer.
  for (const int n : {1, 2, 17, 2047, 2048, 2049, 4096, 6000, 40000}) {
    for (int variant = 0; variant < 4; ++variant) {
      proto::Scan scan;
      scan.set_index(static_cast<uint32_t>(n));
      scan.set_stamp_ns(1'700'000'000'000'000'000LL + n);
      scan.set_record_stamp_ns(1'700'000'000'050'000'000LL);
      scan.set_frame_id("velodyne");
      scan.set_time_source(proto::POINT_TIME_VELODYNE_TIME);
      for (int i = 0; i < n; ++i) {
        scan.add_x(coordinate(rng));
        scan.add_y(coordinate(rng));
        scan.add_z(coordinate(rng));
        scan.add_intensity(static_cast<float>(rng() % 256));
        uint32_t ring = rng() % 16;  // variant 0: every ring below 128 (one byte each)
        if (variant == 1) ring = rng() % 300;
        if (variant >= 2) ring = static_cast<uint32_t>(rng()) >> (rng() % 32);
        scan.add_ring(ring);
        int32_t time = static_cast<int32_t>(rng() % 100'000'000) - 50'000'000;  // +-50 ms
        if (variant == 3) time = static_cast<int32_t>(rng()) >> (rng() % 32);
        scan.add_time_offset_ns(time);
      }
      scan.set_num_dropped_invalid(rng() % 3);
      scan.set_num_dropped_zero_range(rng() % 1000);
      ExpectSameBytes(scan, "n " + std::to_string(n) + " variant " + std::to_string(variant));
    }
  }
}

TEST(ScanEncoder, VarintByteCounts) {
  const std::vector<uint32_t> u = BoundaryUnsigned();
  size_t expected = 0;
  for (const uint32_t v : u) {
    expected += google::protobuf::io::CodedOutputStream::VarintSize32(v);
  }
  EXPECT_EQ(ScanEncoder::UInt32VarintBytes(u.data(), u.size()), expected);
  const std::vector<int32_t> s = BoundarySigned();
  expected = 0;
  for (const int32_t v : s) {
    expected += google::protobuf::io::CodedOutputStream::VarintSize32(
        google::protobuf::internal::WireFormatLite::ZigZagEncode32(v));
  }
  EXPECT_EQ(ScanEncoder::SInt32VarintBytes(s.data(), s.size()), expected);
}

TEST(ScanEncoder, UnknownFieldsAreLeftToProtobuf) {
  proto::Scan scan;
  scan.add_x(1.0f);
  // Field 99, varint 7: parsed into the unknown fields.
  std::string bytes = scan.SerializeAsString() + std::string("\x98\x06\x07", 3);
  proto::Scan parsed;
  ASSERT_TRUE(parsed.ParseFromString(bytes));
  EXPECT_FALSE(ScanEncoder::Supported(parsed));
  EXPECT_TRUE(ScanEncoder::Supported(scan));
}

}  // namespace
}  // namespace tiltcal
