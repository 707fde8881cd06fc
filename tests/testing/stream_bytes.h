#ifndef TILTCAL_TESTS_TESTING_STREAM_BYTES_H_
#define TILTCAL_TESTS_TESTING_STREAM_BYTES_H_

// The records of a stage output, for comparing two runs: the bytes of a
// plain record stream after its header (the header's provenance names the
// input, the command line and the time, so it differs between runs), and
// every record of a stream (plain or LZ4), serialized.

#include <cstdint>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/io/record_stream.h"

namespace tiltcal::testing {

// Bytes after kStreamMagic and the varint-delimited StreamHeader of the
// plain (not LZ4) record stream at `path`; "" with a test failure when it
// is not one.
inline std::string StreamBytesAfterHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  size_t pos = sizeof(kStreamMagic);
  if (bytes.compare(0, pos, kStreamMagic, sizeof(kStreamMagic)) != 0) {
    ADD_FAILURE() << path << " is not a plain record stream";
    return "";
  }
  uint64_t header_size = 0;
  for (int shift = 0; pos < bytes.size() && shift < 64; shift += 7) {
    const auto b = static_cast<uint8_t>(bytes[pos++]);
    header_size |= uint64_t{b & 0x7fu} << shift;
    if ((b & 0x80u) == 0) break;
  }
  if (header_size > bytes.size() - pos) {
    ADD_FAILURE() << path << ": header runs past the end";
    return "";
  }
  return bytes.substr(pos + header_size);
}

// Every record of the stream at `path`, serialized.
template <typename Record>
std::vector<std::string> SerializedRecords(const std::string& path) {
  std::vector<Record> records;
  const Status status = ReadAllRecords<Record>(path, &records);
  EXPECT_TRUE(status.ok()) << status.message();
  std::vector<std::string> out;
  for (const Record& r : records) out.push_back(r.SerializeAsString());
  return out;
}

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_TESTING_STREAM_BYTES_H_
