#include "tests/bag/ros2/ros2_oracle.h"

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "bag/ros1/messages.h"
#include "bag/ros2/cdr_reader.h"
#include "bag/ros2/messages.h"
#include "tests/testing/test_env.h"

namespace tiltcal::testing {

namespace {

std::string Hex(const uint8_t* data, size_t size) {
  static const char kHex[] = "0123456789abcdef";
  std::string out(2 * size, '0');
  for (size_t i = 0; i < size; ++i) {
    out[2 * i] = kHex[data[i] >> 4];
    out[2 * i + 1] = kHex[data[i] & 15];
  }
  return out;
}

std::string HeaderText(const std::string& topic, int64_t record_ns, const bag::Header& h) {
  return topic + " " + std::to_string(record_ns) + " " + std::to_string(h.stamp.sec) + " " +
         std::to_string(h.stamp.nsec) + " frame=" + h.frame_id;
}

// The decoded message in the script's line format, except doubles, which go
// to *values for an exact comparison.
Status Describe(const bag::Message& m, const std::string& type, std::string* line,
                std::vector<double>* values) {
  values->clear();
  const bool ros1 = m.encoding == bag::Encoding::kRos1;  // ROS 1 messages in an MCAP
  if (type == ros2::kImuType || type == ros1::kImuType) {
    bag::ImuMessage imu;
    TILTCAL_RETURN_IF_ERROR(ros1 ? ros1::DecodeImu(m.data, m.size, &imu)
                                 : ros2::DecodeImu(m.data, m.size, &imu));
    *line = "imu " + HeaderText(*m.topic, m.time_ns, imu.header);
    values->insert(values->end(), imu.orientation, imu.orientation + 4);
    values->insert(values->end(), imu.orientation_covariance, imu.orientation_covariance + 9);
    values->insert(values->end(), imu.angular_velocity, imu.angular_velocity + 3);
    values->insert(values->end(), imu.angular_velocity_covariance,
                   imu.angular_velocity_covariance + 9);
    values->insert(values->end(), imu.linear_acceleration, imu.linear_acceleration + 3);
    values->insert(values->end(), imu.linear_acceleration_covariance,
                   imu.linear_acceleration_covariance + 9);
    return Status::Ok();
  }
  if (type == ros2::kPointCloud2Type || type == ros1::kPointCloud2Type) {
    bag::PointCloud2View c;
    TILTCAL_RETURN_IF_ERROR(ros1 ? ros1::DecodePointCloud2(m.data, m.size, &c)
                                 : ros2::DecodePointCloud2(m.data, m.size, &c));
    std::ostringstream out;
    out << "cloud " << HeaderText(*m.topic, m.time_ns, c.header) << " " << c.height << " "
        << c.width << " " << c.is_bigendian << " " << c.point_step << " " << c.row_step << " "
        << c.is_dense << " " << c.fields.size();
    for (const bag::PointField& f : c.fields) {
      out << " " << f.name << " " << f.offset << " " << int{f.datatype} << " " << f.count;
    }
    out << " " << Hex(c.data, c.data_size);
    *line = out.str();
    return Status::Ok();
  }
  std::string data;
  if (ros1) {  // std_msgs/String: uint32 length, the bytes
    uint32_t length = 0;
    if (m.size < 4) return Status::Error("std_msgs/String shorter than its length");
    std::memcpy(&length, m.data, 4);
    if (length != m.size - 4) return Status::Error("std_msgs/String length mismatch");
    data.assign(reinterpret_cast<const char*>(m.data) + 4, length);
    *line = "string " + *m.topic + " " + std::to_string(m.time_ns) + " " + data;
    return Status::Ok();
  }
  ros2::CdrReader r;
  TILTCAL_RETURN_IF_ERROR(r.Open(m.data, m.size));
  TILTCAL_RETURN_IF_ERROR(r.String("data", &data));
  TILTCAL_RETURN_IF_ERROR(r.ExpectEnd("std_msgs/msg/String"));
  *line = "string " + *m.topic + " " + std::to_string(m.time_ns) + " " + data;
  return Status::Ok();
}

// Splits an expected imu line into its text part (the first 6 words) and
// its 37 doubles.
void SplitImuLine(const std::string& line, std::string* text, std::vector<double>* values) {
  std::istringstream in(line);
  std::string word;
  text->clear();
  values->clear();
  for (int i = 0; in >> word; ++i) {
    if (i < 6) {
      *text += (i ? " " : "") + word;
    } else {
      values->push_back(std::strtod(word.c_str(), nullptr));
    }
  }
}

}  // namespace

std::string Ros2OracleMissing() {
  const std::string modules = SourceDir() + "/tests/node_modules";
  if (!FileExists(modules + "/@mcap/core/package.json") ||
      !FileExists(modules + "/sql.js/package.json") ||
      !FileExists(modules + "/@foxglove/rosmsg-serialization/package.json")) {
    return "the npm oracles are not installed in " + modules + " (run scripts/setup.sh)";
  }
  if (RunCommand("node --version >/dev/null 2>&1") != 0) return "no node on PATH";
  return "";
}

bool WriteRos2Bag(const std::string& out, const std::string& args, const std::string& expected,
                  std::string* error) {
  std::string output;
  const std::string command = "node " + SourceDir() + "/tests/oracle/write_ros2_bags.mjs '" +
                              out + "' " + args +
                              (expected.empty() ? "" : " --expected='" + expected + "'") + " 2>&1";
  if (RunCommand(command, &output) != 0) {
    *error = command + ": " + output;
    return false;
  }
  return true;
}

std::string CompareWithExpected(bag::MessageReader* reader, const std::string& expected,
                                int* count) {
  std::ifstream in(expected);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  std::string difference;
  *count = 0;
  Status status = reader->ReadMessages({}, [&](const bag::Message& m) -> Status {
    const size_t i = static_cast<size_t>((*count)++);
    if (i >= lines.size()) return Status::Error("more messages than written");
    std::string line;
    std::vector<double> values;
    TILTCAL_RETURN_IF_ERROR(Describe(m, reader->TopicType(*m.topic), &line, &values));
    std::string want = lines[i];
    std::vector<double> want_values;
    if (line.rfind("imu ", 0) == 0) SplitImuLine(lines[i], &want, &want_values);
    if (line != want || values != want_values) {
      return Status::Error("message " + std::to_string(i) + " differs:\n  read  " +
                           line.substr(0, 300) + "\n  wrote " + want.substr(0, 300));
    }
    return Status::Ok();
  });
  if (!status.ok()) return status.message();
  if (static_cast<size_t>(*count) != lines.size()) {
    return "read " + std::to_string(*count) + " messages, the script wrote " +
           std::to_string(lines.size());
  }
  return "";
}

}  // namespace tiltcal::testing
