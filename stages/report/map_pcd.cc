#include "stages/report/map_pcd.h"

#include <cstring>
#include <map>
#include <sstream>

#include "common/io/atomic_file.h"

namespace tiltcal::report {
namespace {

std::vector<std::string> Words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

}  // namespace

Status ParseMapPcd(const std::string& bytes, const std::string& path,
                   std::vector<Eigen::Vector3f>* points) {
  points->clear();
  std::map<std::string, std::vector<std::string>> header;
  size_t offset = 0;
  while (true) {
    const size_t end = bytes.find('\n', offset);
    if (end == std::string::npos) {
      return Status::Error(path + ": PCD header without a DATA line");
    }
    const std::vector<std::string> words = Words(bytes.substr(offset, end - offset));
    offset = end + 1;
    if (words.empty() || words[0][0] == '#') continue;
    header[words[0]] = std::vector<std::string>(words.begin() + 1, words.end());
    if (words[0] == "DATA") break;
  }
  for (const char* key : {"FIELDS", "SIZE", "TYPE", "POINTS"}) {
    if (header[key].empty()) return Status::Error(path + ": PCD header has no " + key + " line");
  }
  const auto& fields = header["FIELDS"];
  const auto& sizes = header["SIZE"];
  const auto& types = header["TYPE"];
  std::vector<std::string> counts = header["COUNT"];
  if (counts.empty()) counts.assign(fields.size(), "1");
  if (sizes.size() != fields.size() || types.size() != fields.size() ||
      counts.size() != fields.size()) {
    return Status::Error(path + ": PCD header: FIELDS, SIZE, TYPE and COUNT differ in length");
  }
  if (header["DATA"] != std::vector<std::string>{"binary"}) {
    return Status::Error(path + ": PCD is not DATA binary (the maps of tiltcal_calibrate are)");
  }
  size_t point_size = 0;
  for (size_t i = 0; i < fields.size(); ++i) {
    const bool xyz = i < 3;
    if (xyz && (fields[i] != std::string(1, "xyz"[i]) || sizes[i] != "4" || types[i] != "F" ||
                counts[i] != "1")) {
      return Status::Error(path + ": PCD fields must start with x y z (float32)");
    }
    int size = 0, count = 0;
    if (std::sscanf(sizes[i].c_str(), "%d", &size) != 1 ||
        std::sscanf(counts[i].c_str(), "%d", &count) != 1 || size <= 0 || size > 8 ||
        count <= 0 || count > 1024) {
      return Status::Error(path + ": PCD field " + fields[i] + " has a bad SIZE or COUNT");
    }
    point_size += static_cast<size_t>(size) * static_cast<size_t>(count);
  }
  if (fields.size() < 3) {
    return Status::Error(path + ": PCD fields must start with x y z (float32)");
  }
  unsigned long long n = 0;
  if (std::sscanf(header["POINTS"][0].c_str(), "%llu", &n) != 1) {
    return Status::Error(path + ": PCD POINTS is not a number");
  }
  const size_t available = (bytes.size() - offset) / point_size;
  if (n > available) {
    return Status::Error(path + ": PCD truncated: POINTS " + std::to_string(n) + ", data for " +
                         std::to_string(available));
  }
  points->resize(n);
  for (size_t i = 0; i < n; ++i) {
    std::memcpy((*points)[i].data(), bytes.data() + offset + i * point_size, 12);
  }
  return Status::Ok();
}

Status ReadMapPcd(const std::string& path, std::vector<Eigen::Vector3f>* points) {
  std::string bytes;
  TILTCAL_RETURN_IF_ERROR(ReadFileToString(path, &bytes));
  return ParseMapPcd(bytes, path, points);
}

}  // namespace tiltcal::report
