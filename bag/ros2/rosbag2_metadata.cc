#include "bag/ros2/rosbag2_metadata.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <sstream>

#include "bag/ros2/yaml_scalar.h"
#include "common/io/input_file.h"

namespace tiltcal::ros2 {

Rosbag2Metadata ParseRosbag2Metadata(const std::string& text) {
  Rosbag2Metadata metadata;
  std::istringstream in(text);
  std::string line;
  bool in_list = false;
  while (std::getline(in, line)) {
    const std::string t = TrimYamlSpace(line);
    if (in_list && t.rfind("- ", 0) == 0) {
      metadata.relative_file_paths.push_back(UnquoteYamlScalar(TrimYamlSpace(t.substr(2))));
      continue;
    }
    in_list = false;
    if (t.rfind("relative_file_paths:", 0) == 0) {
      const std::string rest = TrimYamlSpace(t.substr(20));
      if (rest.empty()) {
        in_list = true;
      } else if (rest.front() == '[' && rest.back() == ']') {
        std::string item;
        for (char c : rest.substr(1, rest.size() - 2) + ",") {
          if (c != ',') {
            item += c;
          } else if (!TrimYamlSpace(item).empty()) {
            metadata.relative_file_paths.push_back(UnquoteYamlScalar(TrimYamlSpace(item)));
            item.clear();
          }
        }
      }
    } else if (t.rfind("storage_identifier:", 0) == 0) {
      metadata.storage_identifier = UnquoteYamlScalar(TrimYamlSpace(t.substr(19)));
    } else if (t.rfind("compression_format:", 0) == 0) {
      metadata.compression_format = UnquoteYamlScalar(TrimYamlSpace(t.substr(19)));
    }
  }
  return metadata;
}

Status ReadRosbag2Metadata(const std::string& file, Rosbag2Metadata* metadata) {
  int fd = -1;
  uint64_t size = 0;
  TILTCAL_RETURN_IF_ERROR(OpenInputFile(file, &fd, &size));
  if (size > kMaxRosbag2MetadataBytes) {
    ::close(fd);
    return Status::Error(file + ": " + std::to_string(size) + " bytes, more than the " +
                         std::to_string(kMaxRosbag2MetadataBytes) +
                         " bytes a rosbag2 metadata.yaml can hold");
  }
  // At most the limit is read, also when the file grows meanwhile.
  std::string text(kMaxRosbag2MetadataBytes + 1, '\0');
  size_t got = 0;
  while (got < text.size()) {
    const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int error = errno;
      ::close(fd);
      return Status::Error(file + ": cannot read: " + std::strerror(error));
    }
    if (n == 0) break;
    got += static_cast<size_t>(n);
  }
  ::close(fd);
  if (got > kMaxRosbag2MetadataBytes) {
    return Status::Error(file + ": more than the " + std::to_string(kMaxRosbag2MetadataBytes) +
                         " bytes a rosbag2 metadata.yaml can hold");
  }
  text.resize(got);
  *metadata = ParseRosbag2Metadata(text);
  return Status::Ok();
}

}  // namespace tiltcal::ros2
