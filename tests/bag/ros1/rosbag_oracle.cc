#include "tests/bag/ros1/rosbag_oracle.h"

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "tests/testing/test_env.h"

namespace tiltcal::ros1::testing {

std::vector<const DumpedMessage*> BagDump::Topic(const std::string& topic) const {
  std::vector<const DumpedMessage*> out;
  for (const DumpedMessage& m : messages) {
    if (m.topic == topic) out.push_back(&m);
  }
  return out;
}

uint32_t Crc32(const void* data, size_t size) {
  static uint32_t table[256];
  static bool init = false;
  if (!init) {
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      table[i] = c;
    }
    init = true;
  }
  uint32_t crc = 0xFFFFFFFFu;
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) crc = table[(crc ^ p[i]) & 0xFF] ^ (crc >> 8);
  return crc ^ 0xFFFFFFFFu;
}

bool DumpBagWithRosbag(const std::string& bag, const std::string& dump_path,
                       const std::vector<int>& cloud_indices, BagDump* dump, std::string* error) {
  std::string indices;
  for (size_t i = 0; i < cloud_indices.size(); ++i) {
    indices += (i ? "," : "") + std::to_string(cloud_indices[i]);
  }
  const std::string command = std::string(tiltcal::testing::kDebianPython) + " " +
                              tiltcal::testing::SourceDir() + "/tests/oracle/read_sim_bag.py " +
                              bag + " " + dump_path + " '" + indices + "' 2>&1";
  std::string output;
  if (tiltcal::testing::RunCommand(command, &output) != 0) {
    *error = "oracle failed: " + output;
    return false;
  }
  std::ifstream in(dump_path);
  std::string line;
  DumpedMessage* last = nullptr;
  *dump = BagDump();
  dump->messages.reserve(4096);
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string kind;
    s >> kind;
    if (kind == "compression") {
      s >> dump->compression;
    } else if (kind == "msg") {
      dump->messages.emplace_back();
      last = &dump->messages.back();
      s >> last->topic >> last->type >> last->record_ns >> last->stamp_ns >> last->seq >>
          last->frame_id >> last->crc32 >> last->size;
    } else if (kind == "imu" && last != nullptr) {
      for (double& v : last->imu) {
        std::string token;
        s >> token;
        v = std::strtod(token.c_str(), nullptr);
      }
    } else if (kind == "cloud" && last != nullptr) {
      int dense = 0, big = 0;
      s >> last->cloud_index >> last->height >> last->width >> last->point_step >>
          last->row_step >> dense >> big;
      last->is_dense = dense != 0;
      last->is_bigendian = big != 0;
    } else if (kind == "field" && last != nullptr) {
      DumpedField f;
      s >> f.name >> f.offset >> f.datatype >> f.count;
      last->fields.push_back(f);
    } else if (kind == "p" && last != nullptr) {
      std::vector<double> values;
      std::string token;
      while (s >> token) values.push_back(std::strtod(token.c_str(), nullptr));
      last->points.push_back(std::move(values));
    }
    if (!s && kind != "p") {
      *error = "cannot parse oracle line: " + line;
      return false;
    }
  }
  return true;
}

}  // namespace tiltcal::ros1::testing
