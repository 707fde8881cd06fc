#ifndef TILTCAL_BAG_ROS2_YAML_SCALAR_H_
#define TILTCAL_BAG_ROS2_YAML_SCALAR_H_

// The two scalar rules of the line-wise metadata.yaml readers
// (rosbag2_metadata.h, rosbag2_metadata_figures.h).

#include <string>

namespace tiltcal::ros2 {

// `s` without leading and trailing spaces, tabs and carriage returns.
std::string TrimYamlSpace(const std::string& s);

// `s` without one pair of matching enclosing quotes ("..." or '...').
std::string UnquoteYamlScalar(const std::string& s);

}  // namespace tiltcal::ros2

#endif  // TILTCAL_BAG_ROS2_YAML_SCALAR_H_
