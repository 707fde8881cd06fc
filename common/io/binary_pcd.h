#ifndef TILTCAL_COMMON_IO_BINARY_PCD_H_
#define TILTCAL_COMMON_IO_BINARY_PCD_H_

#include <cstddef>
#include <string>
#include <vector>

namespace tiltcal {

// One field of a PCD point: its name, its size in bytes and its type
// ('F' float, 'U' unsigned, 'I' signed integer), one element each.
struct PcdField {
  std::string name;
  int size_bytes = 4;
  char type = 'F';
};

// The header of a binary PCD (v0.7, the format of pcl_viewer and
// CloudCompare) of `num_points` unorganised points with `fields` packed in
// that order, up to and including the line "DATA binary": the points
// follow it as num_points x (sum of the field sizes) bytes, little-endian.
// The header is the one PCL's PCDWriter::generateHeaderBinary writes for a
// viewpoint at the origin.
std::string BinaryPcdHeader(const std::vector<PcdField>& fields, size_t num_points);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_BINARY_PCD_H_
