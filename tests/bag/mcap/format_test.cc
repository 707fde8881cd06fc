#include "bag/mcap/format.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace tiltcal::mcap {
namespace {

const uint8_t* Bytes(const std::string& s) { return reinterpret_cast<const uint8_t*>(s.data()); }

TEST(McapCrc32, CheckValueAndEveryLengthAgainstTheBytewiseDefinition) {
  const std::string check = "123456789";
  EXPECT_EQ(Crc32(Bytes(check), check.size()), 0xCBF43926u);  // CRC-32/ISO-HDLC check value
  // The 8-bytes-per-step loop against the plain bitwise CRC, lengths 0..40,
  // and continuing a CRC over two pieces.
  std::string data;
  for (int i = 0; i < 40; ++i) data += static_cast<char>(i * 37 + 11);
  for (size_t n = 0; n <= data.size(); ++n) {
    uint32_t bitwise = ~0u;
    for (size_t i = 0; i < n; ++i) {
      bitwise ^= static_cast<uint8_t>(data[i]);
      for (int k = 0; k < 8; ++k) bitwise = (bitwise & 1) ? 0xEDB88320u ^ (bitwise >> 1) : bitwise >> 1;
    }
    EXPECT_EQ(Crc32(Bytes(data), n), ~bitwise) << n;
    EXPECT_EQ(Crc32(Bytes(data) + n / 2, n - n / 2, Crc32(Bytes(data), n / 2)), ~bitwise) << n;
  }
}

TEST(McapFieldReader, RecordThatRunsShortNamesTheField) {
  const std::vector<uint8_t> content = {1, 0, 5, 0, 0, 0, 'a', 'b'};  // id 1, name of 5 bytes
  SchemaRecord schema;
  const Status status = ParseSchema(content.data(), content.size(), &schema);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("schema name"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace tiltcal::mcap
