#include "stages/report/png_encoder.h"

#include <zlib.h>

namespace tiltcal {
namespace {

void AppendBigEndian32(uint32_t value, std::string* out) {
  for (int shift = 24; shift >= 0; shift -= 8) {
    out->push_back(static_cast<char>((value >> shift) & 0xff));
  }
}

// length, type, data, CRC-32 of type + data.
void AppendChunk(const char type[4], const std::string& data, std::string* out) {
  AppendBigEndian32(static_cast<uint32_t>(data.size()), out);
  const std::string body = std::string(type, 4) + data;
  out->append(body);
  AppendBigEndian32(static_cast<uint32_t>(crc32(
                        0L, reinterpret_cast<const Bytef*>(body.data()),
                        static_cast<uInt>(body.size()))),
                    out);
}

}  // namespace

std::string EncodePng(const GrayImage& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<size_t>(image.width) * image.height) {
    return "";
  }
  std::string raw;
  raw.reserve(static_cast<size_t>(image.width + 1) * image.height);
  for (int row = 0; row < image.height; ++row) {
    raw.push_back(0);  // filter type None
    const auto* begin = image.pixels.data() + static_cast<size_t>(row) * image.width;
    raw.append(reinterpret_cast<const char*>(begin), static_cast<size_t>(image.width));
  }
  uLongf compressed_size = compressBound(static_cast<uLong>(raw.size()));
  std::string compressed(compressed_size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(compressed.data()), &compressed_size,
                reinterpret_cast<const Bytef*>(raw.data()), static_cast<uLong>(raw.size()),
                Z_BEST_COMPRESSION) != Z_OK) {
    return "";
  }
  compressed.resize(compressed_size);

  std::string header;
  AppendBigEndian32(static_cast<uint32_t>(image.width), &header);
  AppendBigEndian32(static_cast<uint32_t>(image.height), &header);
  // Bit depth 8, greyscale, deflate, filter method 0, no interlace.
  header += std::string("\x08\x00\x00\x00\x00", 5);
  std::string png("\x89PNG\r\n\x1a\n", 8);
  AppendChunk("IHDR", header, &png);
  AppendChunk("IDAT", compressed, &png);
  AppendChunk("IEND", "", &png);
  return png;
}

}  // namespace tiltcal
