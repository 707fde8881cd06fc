#ifndef TILTCAL_STAGES_INSPECT_BAG_SURVEY_H_
#define TILTCAL_STAGES_INSPECT_BAG_SURVEY_H_

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "bag/input/static_transforms.h"
#include "common/status.h"
#include "stages/inspect/point_cloud_sample.h"

namespace tiltcal::inspect {

struct BagSurveyOptions {
  std::string imu_topic;    // "" = the only sensor_msgs/Imu topic
  std::string lidar_topic;  // "" = the only PointCloud2 or Livox CustomMsg topic
  uint32_t max_sampled_scans = 60;
  uint32_t point_stride = 4;
};

// The raw material of the pre-flight check, read from any input decode reads
// (a ROS 1 bag, MCAP, a rosbag2 folder or .db3, a folder of bag files:
// bag/input/bag_input.h) in one pass: every IMU message, every scan's stamp
// and point count, the points of up to max_sampled_scans scans spread
// evenly over the bag (PointCloud2 or Livox CustomMsg), and what /tf_static
// says about the extrinsic (a short read of the bag's start).
struct BagSurvey {
  std::string path;
  std::string format;  // "ROS 1 bag", "MCAP", "2 files (ROS 1 bag, MCAP)", ...
  uint64_t file_size = 0;  // of every file read
  bool indexed = true;
  std::vector<std::string> topics;  // every topic, sorted
  // A topic is "" when it cannot be chosen; *_problem then says why.
  std::string imu_topic, lidar_topic;
  std::string imu_problem, lidar_problem;

  // IMU messages in record order, values in the published units.
  std::vector<int64_t> imu_stamp_ns, imu_record_ns;
  std::vector<Eigen::Vector3d> gyro, accel;

  // Scans in record order.
  std::vector<int64_t> scan_stamp_ns, scan_record_ns;
  std::vector<int64_t> scan_num_points;  // width · height
  CloudLayout layout;                    // of the first scan
  std::vector<CloudSample> sampled_scans;

  // /tf_static (bag/input/static_transforms.h); empty when a topic is missing.
  bag::StaticTransforms tf_static;
};

// Opens the bag and reads it. A topic the options name that is absent or of
// another type, or several candidates without a choice, is a problem (the
// check reports it), not an error; errors are a bag that cannot be read or a
// message that cannot be decoded, and name the file (and topic, message).
Status SurveyBag(const std::string& path, const BagSurveyOptions& options, BagSurvey* survey);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_BAG_SURVEY_H_
