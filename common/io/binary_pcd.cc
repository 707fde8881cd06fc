#include "common/io/binary_pcd.h"

#include <fmt/format.h>

namespace tiltcal {

std::string BinaryPcdHeader(const std::vector<PcdField>& fields, size_t num_points) {
  std::string names, sizes, types, counts;
  for (const PcdField& field : fields) {
    names += " " + field.name;
    sizes += fmt::format(" {}", field.size_bytes);
    types += fmt::format(" {}", field.type);
    counts += " 1";
  }
  return fmt::format(
      "# .PCD v0.7 - Point Cloud Data file format\n"
      "VERSION 0.7\n"
      "FIELDS{}\n"
      "SIZE{}\n"
      "TYPE{}\n"
      "COUNT{}\n"
      "WIDTH {}\n"
      "HEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\n"
      "POINTS {}\n"
      "DATA binary\n",
      names, sizes, types, counts, num_points, num_points);
}

}  // namespace tiltcal
