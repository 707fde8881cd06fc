#ifndef TILTCAL_STAGES_REPORT_PNG_ENCODER_H_
#define TILTCAL_STAGES_REPORT_PNG_ENCODER_H_

// PNG (ISO/IEC 15948) encoding of an 8-bit greyscale image in memory:
// signature, IHDR (colour type 0, bit depth 8, no interlace), one IDAT of
// the zlib-compressed rows (each with filter type 0, "None"), IEND; chunk
// CRCs by zlib's crc32. For the report page's images (data: URIs).

#include <cstdint>
#include <string>
#include <vector>

namespace tiltcal {

struct GrayImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> pixels;  // row-major, row 0 at the top; 0 black, 255 white
};

// The PNG file's bytes; "" when the image is empty or its pixel count
// does not match width x height.
std::string EncodePng(const GrayImage& image);

}  // namespace tiltcal

#endif  // TILTCAL_STAGES_REPORT_PNG_ENCODER_H_
