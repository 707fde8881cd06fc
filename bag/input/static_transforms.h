#ifndef TILTCAL_BAG_INPUT_STATIC_TRANSFORMS_H_
#define TILTCAL_BAG_INPUT_STATIC_TRANSFORMS_H_

// What a bag's /tf_static says about the IMU-from-LiDAR extrinsic. Many
// recordings carry the vehicle's URDF as static transforms on /tf_static
// (tf2_msgs/TFMessage in ROS 1 and ROS 2; tf/tfMessage in old ROS 1 bags,
// the same layout). Every message of the topic is read; a child frame
// published again replaces its earlier transform, as in tf2 (a different
// value is a warning). The IMU's and the LiDAR's frames are the
// header.frame_id of the first message of each topic; the transform between
// them is the chain of static transforms joining the two frames, walked in
// either direction (common/geometry/transform_tree.h):
//   imu_from_lidar = T_imu←f1 · … · T_fn←lidar,  p_imu = C_bl p_lidar + r_b^{lb}.
// A TransformStamped (parent = header.frame_id, child = child_frame_id) is
// the pose of the child in the parent, p_parent = R p_child + t.
// Transforms with non-finite values, a quaternion whose norm is not 1
// within 1e-3 (else normalised), or an empty frame are skipped with a
// warning. No chain, no /tf_static, or both sensors in one frame is not an
// error: the result says so in its summary.

#include <cstdint>
#include <string>
#include <vector>

#include "bag/message_reader.h"
#include "common/geometry/transform_tree.h"
#include "common/status.h"
#include "tiltcal/proto/stream.pb.h"

namespace tiltcal::bag {

struct StaticTransforms {
  std::string tf_topic;      // the topic read; "" when the bag has none
  std::string imu_frame_id;  // as in the bag ("" when the topic has no message)
  std::string lidar_frame_id;
  int64_t num_messages = 0;    // TFMessages read
  int64_t num_transforms = 0;  // transforms in them
  // The transforms after replacements, in order of first publication.
  std::vector<geometry::FrameEdge> edges;
  bool found = false;  // a chain joins the two frames (and they differ)
  geometry::FrameChain imu_from_lidar;  // target: IMU frame, source: LiDAR frame
  std::vector<std::string> warnings;    // transforms skipped or replaced by other values
  // One sentence: "imu_from_lidar along imu_link <- base_link <- velodyne:
  // rotation ..., translation ... m" or "no tf_static transform joins 'imu'
  // and 'velodyne' (...)".
  std::string summary;
};

// Reads every kTfStaticTopic message ("tf_static" without the leading '/'
// is taken too) and the first message of `imu_topic` and
// of `lidar_topic` (sensor_msgs/Imu, PointCloud2 or a Livox CustomMsg, in
// ROS 1 or CDR encoding), stopping once it has all of them (tf_static is
// recorded at the start of a bag: usually one pass over the first chunk).
// Errors: a message that cannot be decoded, named by file, topic and
// position.
Status ReadStaticTransforms(MessageReader& reader, const std::string& imu_topic,
                            const std::string& lidar_topic, StaticTransforms* result);

// The provenance record of `transforms` (proto TfStaticExtrinsic).
proto::TfStaticExtrinsic ToProto(const StaticTransforms& transforms);

}  // namespace tiltcal::bag

#endif  // TILTCAL_BAG_INPUT_STATIC_TRANSFORMS_H_
