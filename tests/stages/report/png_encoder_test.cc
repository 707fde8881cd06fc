#include "stages/report/png_encoder.h"

#include <png.h>

#include <gtest/gtest.h>

namespace tiltcal {
namespace {

// Decoded by libpng (an independent reader): the same size, greyscale, the
// same pixels.
TEST(PngEncoder, LibpngDecodesTheSamePixels) {
  GrayImage image;
  image.width = 7;
  image.height = 3;
  for (int i = 0; i < image.width * image.height; ++i) {
    image.pixels.push_back(static_cast<uint8_t>((37 * i) % 256));
  }
  const std::string png = EncodePng(image);
  ASSERT_FALSE(png.empty());
  png_image decoded{};
  decoded.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_memory(&decoded, png.data(), png.size()))
      << decoded.message;
  EXPECT_EQ(decoded.width, 7u);
  EXPECT_EQ(decoded.height, 3u);
  EXPECT_EQ(decoded.format, static_cast<png_uint_32>(PNG_FORMAT_GRAY));
  std::vector<uint8_t> pixels(PNG_IMAGE_SIZE(decoded));
  ASSERT_TRUE(png_image_finish_read(&decoded, nullptr, pixels.data(), 0, nullptr))
      << decoded.message;
  EXPECT_EQ(pixels, image.pixels);
}

TEST(PngEncoder, EmptyOrInconsistentImageGivesNothing) {
  EXPECT_EQ(EncodePng(GrayImage{}), "");
  GrayImage short_rows;
  short_rows.width = 4;
  short_rows.height = 2;
  short_rows.pixels.assign(7, 0);
  EXPECT_EQ(EncodePng(short_rows), "");
}

}  // namespace
}  // namespace tiltcal
