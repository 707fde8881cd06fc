#ifndef TILTCAL_TESTS_BAG_ROS2_ROS2_ORACLE_H_
#define TILTCAL_TESTS_BAG_ROS2_ROS2_ORACLE_H_

// The ROS 2 oracle: bags written by the public npm libraries through
// tests/oracle/write_ros2_bags.mjs (tests/node_modules, installed by
// scripts/setup.sh), and the check that a bag::MessageReader gives back
// every value the script says it wrote.

#include <string>

#include "bag/message_reader.h"

namespace tiltcal::testing {

// "" when node and tests/node_modules are there, else why the tests skip.
std::string Ros2OracleMissing();

// Runs write_ros2_bags.mjs OUT ARGS --expected=EXPECTED; false with the
// script's output in *error when it fails.
bool WriteRos2Bag(const std::string& out, const std::string& args, const std::string& expected,
                  std::string* error);

// Reads every message of `reader` and compares it with the lines of
// `expected` (same order): topic, record time, header, every Imu value,
// every PointCloud2 field and data byte, the std_msgs/String data. Returns
// "" when all agree, else the first difference. *count gets the messages read.
std::string CompareWithExpected(bag::MessageReader* reader, const std::string& expected,
                                int* count);

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_BAG_ROS2_ROS2_ORACLE_H_
