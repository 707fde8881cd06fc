#include "bag/ros1/message_encoding.h"

#include <cstring>
#include <string>

#include "bag/ros1/format.h"

namespace tiltcal::ros1 {

// Full message definitions as recorded by rosbag (the top-level .msg, then
// each dependency after a line of 80 '=' and "MSG: pkg/Type"), from
// ros/common_msgs (sensor_msgs, geometry_msgs) and ros/std_msgs, noetic, in
// pieces: the top-level .msg, std_msgs/Header (the first dependency of both
// messages), the other dependencies.
const char kHeaderDefinition[] = R"msgdef(================================================================================
MSG: std_msgs/Header
# Standard metadata for higher-level stamped data types.
# This is generally used to communicate timestamped data 
# in a particular coordinate frame.
# 
# sequence ID: consecutively increasing ID 
uint32 seq
#Two-integer timestamp that is expressed as:
# * stamp.sec: seconds (stamp_secs) since epoch (in Python the variable is called 'secs')
# * stamp.nsec: nanoseconds since stamp_secs (in Python the variable is called 'nsecs')
# time-handling sugar is provided by the client library
time stamp
#Frame this data is associated with
string frame_id

)msgdef";

const char kImuDefinitionTop[] = R"msgdef(# This is a message to hold data from an IMU (Inertial Measurement Unit)
#
# Accelerations should be in m/s^2 (not in g's), and rotational velocity should be in rad/sec
#
# If the covariance of the measurement is known, it should be filled in (if all you know is the 
# variance of each measurement, e.g. from the datasheet, just put those along the diagonal)
# A covariance matrix of all zeros will be interpreted as "covariance unknown", and to use the
# data a covariance will have to be assumed or gotten from some other source
#
# If you have no estimate for one of the data elements (e.g. your IMU doesn't produce an orientation 
# estimate), please set element 0 of the associated covariance matrix to -1
# If you are interpreting this message, please check for a value of -1 in the first element of each 
# covariance matrix, and disregard the associated estimate.

Header header

geometry_msgs/Quaternion orientation
float64[9] orientation_covariance # Row major about x, y, z axes

geometry_msgs/Vector3 angular_velocity
float64[9] angular_velocity_covariance # Row major about x, y, z axes

geometry_msgs/Vector3 linear_acceleration
float64[9] linear_acceleration_covariance # Row major x, y z 

)msgdef";
const char kImuDefinitionDependencies[] = R"msgdef(================================================================================
MSG: geometry_msgs/Quaternion
# This represents an orientation in free space in quaternion form.

float64 x
float64 y
float64 z
float64 w

================================================================================
MSG: geometry_msgs/Vector3
# This represents a vector in free space. 
# It is only meant to represent a direction. Therefore, it does not
# make sense to apply a translation to it (e.g., when applying a 
# generic rigid transformation to a Vector3, tf2 will only apply the
# rotation). If you want your data to be translatable too, use the
# geometry_msgs/Point message instead.

float64 x
float64 y
float64 z)msgdef";

const char kPointCloud2DefinitionTop[] = R"msgdef(# This message holds a collection of N-dimensional points, which may
# contain additional information such as normals, intensity, etc. The
# point data is stored as a binary blob, its layout described by the
# contents of the "fields" array.

# The point cloud data may be organized 2d (image-like) or 1d
# (unordered). Point clouds organized as 2d images may be produced by
# camera depth sensors such as stereo or time-of-flight.

# Time of sensor data acquisition, and the coordinate frame ID (for 3d
# points).
Header header

# 2D structure of the point cloud. If the cloud is unordered, height is
# 1 and width is the length of the point cloud.
uint32 height
uint32 width

# Describes the channels and their layout in the binary data blob.
PointField[] fields

bool    is_bigendian # Is this data bigendian?
uint32  point_step   # Length of a point in bytes
uint32  row_step     # Length of a row in bytes
uint8[] data         # Actual point data, size is (row_step*height)

bool is_dense        # True if there are no invalid points

)msgdef";
const char kPointCloud2DefinitionDependencies[] = R"msgdef(================================================================================
MSG: sensor_msgs/PointField
# This message holds the description of one point entry in the
# PointCloud2 message format.
uint8 INT8    = 1
uint8 UINT8   = 2
uint8 INT16   = 3
uint8 UINT16  = 4
uint8 INT32   = 5
uint8 UINT32  = 6
uint8 FLOAT32 = 7
uint8 FLOAT64 = 8

string name      # Name of field
uint32 offset    # Offset from start of point struct
uint8  datatype  # Datatype enumeration, see above
uint32 count     # How many elements in the field
)msgdef";

const MessageType& ImuMessageType() {
  static const std::string kDefinition =
      std::string(kImuDefinitionTop) + kHeaderDefinition + kImuDefinitionDependencies;
  static const MessageType kType{kImuType, "6a62c6daae103f4ff57a132d6f95cec2",
                                 kDefinition.c_str()};
  return kType;
}

const MessageType& PointCloud2MessageType() {
  static const std::string kDefinition = std::string(kPointCloud2DefinitionTop) +
                                         kHeaderDefinition + kPointCloud2DefinitionDependencies;
  static const MessageType kType{kPointCloud2Type, "1158d486dd51d683ce2f1be655c3c181",
                                 kDefinition.c_str()};
  return kType;
}

// livox_ros_driver msg/CustomMsg.msg and msg/CustomPoint.msg; the MD5 is
// the one genpy computes from this text (that of the driver's messages).
const char kLivoxCustomMsgDefinitionTop[] = R"msgdef(# Livox publish pointcloud msg format.

Header header             # ROS standard message header
uint64 timebase           # The time of first point
uint32 point_num          # Total number of pointclouds
uint8  lidar_id           # Lidar device id number
uint8[3]  rsvd            # Reserved use
CustomPoint[] points      # Pointcloud data

)msgdef";

const char kLivoxCustomPointDefinition[] = R"msgdef(================================================================================
MSG: livox_ros_driver/CustomPoint
# Livox costom pointcloud format.

uint32 offset_time      # offset time relative to the base time
float32 x               # X axis, unit:m
float32 y               # Y axis, unit:m
float32 z               # Z axis, unit:m
uint8 reflectivity      # reflectivity, 0~255
uint8 tag               # livox tag
uint8 line              # laser number in lidar
)msgdef";

const MessageType& LivoxCustomMsgMessageType() {
  static const std::string kDefinition =
      std::string(kLivoxCustomMsgDefinitionTop) + kHeaderDefinition + kLivoxCustomPointDefinition;
  static const MessageType kType{kLivoxCustomMsgType, "e4d6829bdfe657cb6c21a746c86b21a6",
                                 kDefinition.c_str()};
  return kType;
}

// tf2_msgs/TFMessage and geometry_msgs/TransformStamped, Transform, as in
// ros/geometry2 and ros/common_msgs (noetic); the MD5 is genpy's.
const char kTfMessageDefinitionTop[] = R"msgdef(geometry_msgs/TransformStamped[] transforms

================================================================================
MSG: geometry_msgs/TransformStamped
# This expresses a transform from coordinate frame header.frame_id
# to the coordinate frame child_frame_id
#
# This message is mostly used by the 
# <a href="http://wiki.ros.org/tf">tf</a> package. 
# See its documentation for more information.

Header header
string child_frame_id # the frame id of the child frame
Transform transform

)msgdef";
const char kTfMessageDefinitionDependencies[] = R"msgdef(================================================================================
MSG: geometry_msgs/Transform
# This represents the transform between two coordinate frames in free space.

Vector3 translation
Quaternion rotation

================================================================================
MSG: geometry_msgs/Vector3
# This represents a vector in free space. 
# It is only meant to represent a direction. Therefore, it does not
# make sense to apply a translation to it (e.g., when applying a 
# generic rigid transformation to a Vector3, tf2 will only apply the
# rotation). If you want your data to be translatable too, use the
# geometry_msgs/Point message instead.

float64 x
float64 y
float64 z
================================================================================
MSG: geometry_msgs/Quaternion
# This represents an orientation in free space in quaternion form.

float64 x
float64 y
float64 z
float64 w
)msgdef";

const MessageType& TfMessageType() {
  static const std::string kDefinition = std::string(kTfMessageDefinitionTop) +
                                         kHeaderDefinition + kTfMessageDefinitionDependencies;
  static const MessageType kType{kTfMessageType, "94810edda583a504dfda3829e70d7eec",
                                 kDefinition.c_str()};
  return kType;
}

namespace {

void AppendString(std::string* out, const std::string& s) {
  AppendU32Le(out, static_cast<uint32_t>(s.size()));
  out->append(s);
}

void AppendVector3(std::string* out, const Eigen::Vector3d& v) {
  AppendLe(out, v.x());
  AppendLe(out, v.y());
  AppendLe(out, v.z());
}

// float64[9], diagonal.
void AppendCovariance(std::string* out, double diagonal, double first) {
  for (int i = 0; i < 9; ++i) {
    double value = (i % 4 == 0) ? diagonal : 0.0;
    if (i == 0) value = first;
    AppendLe(out, value);
  }
}

}  // namespace

bool AppendHeader(std::string* out, uint32_t seq, int64_t stamp_ns, const std::string& frame_id) {
  RosTime t;
  if (!NsToRosTime(stamp_ns, &t)) return false;
  AppendU32Le(out, seq);
  AppendRosTime(out, t);
  AppendString(out, frame_id);
  return true;
}

bool SerializeImu(uint32_t seq, int64_t stamp_ns, const std::string& frame_id,
                  const Eigen::Vector3d& angular_velocity_radps,
                  const Eigen::Vector3d& linear_acceleration_mps2, double gyro_variance,
                  double accel_variance, std::string* out) {
  out->clear();
  out->reserve(320 + frame_id.size());
  if (!AppendHeader(out, seq, stamp_ns, frame_id)) return false;
  // orientation (x, y, z, w): not provided.
  AppendLe(out, 0.0);
  AppendLe(out, 0.0);
  AppendLe(out, 0.0);
  AppendLe(out, 1.0);
  AppendCovariance(out, 0.0, -1.0);
  AppendVector3(out, angular_velocity_radps);
  AppendCovariance(out, gyro_variance, gyro_variance);
  AppendVector3(out, linear_acceleration_mps2);
  AppendCovariance(out, accel_variance, accel_variance);
  return true;
}

bool SerializePointCloud2(uint32_t seq, int64_t stamp_ns, const std::string& frame_id,
                          uint32_t height, uint32_t width, const std::vector<PointField>& fields,
                          uint32_t point_step, const std::string& data, bool is_dense,
                          std::string* out) {
  out->clear();
  out->reserve(data.size() + 64 + 32 * fields.size() + frame_id.size());
  if (!AppendHeader(out, seq, stamp_ns, frame_id)) return false;
  AppendU32Le(out, height);
  AppendU32Le(out, width);
  AppendU32Le(out, static_cast<uint32_t>(fields.size()));
  for (const PointField& f : fields) {
    AppendString(out, f.name);
    AppendU32Le(out, f.offset);
    out->push_back(static_cast<char>(f.datatype));
    AppendU32Le(out, f.count);
  }
  out->push_back(0);  // is_bigendian
  AppendU32Le(out, point_step);
  AppendU32Le(out, width * point_step);  // row_step
  AppendU32Le(out, static_cast<uint32_t>(data.size()));
  out->append(data);
  out->push_back(is_dense ? 1 : 0);
  return true;
}

bool SerializeLivoxCustomMsg(uint32_t seq, int64_t timebase_ns, const std::string& frame_id,
                             uint8_t lidar_id, const std::vector<LivoxPoint>& points,
                             std::string* out) {
  out->clear();
  out->reserve(points.size() * 19 + 64 + frame_id.size());
  if (timebase_ns < 0 || !AppendHeader(out, seq, timebase_ns, frame_id)) return false;
  AppendLe(out, static_cast<uint64_t>(timebase_ns));
  AppendU32Le(out, static_cast<uint32_t>(points.size()));  // point_num
  out->push_back(static_cast<char>(lidar_id));
  out->append(3, '\0');  // rsvd
  AppendU32Le(out, static_cast<uint32_t>(points.size()));
  for (const LivoxPoint& p : points) {
    AppendU32Le(out, p.offset_time);
    AppendLe(out, p.x);
    AppendLe(out, p.y);
    AppendLe(out, p.z);
    out->push_back(static_cast<char>(p.reflectivity));
    out->push_back(static_cast<char>(p.tag));
    out->push_back(static_cast<char>(p.line));
  }
  return true;
}

void SerializeTfMessage(const TfMessage& msg, std::string* out) {
  out->clear();
  AppendU32Le(out, static_cast<uint32_t>(msg.transforms.size()));
  for (const TransformStamped& t : msg.transforms) {
    AppendU32Le(out, t.header.seq);
    AppendRosTime(out, t.header.stamp);
    AppendString(out, t.header.frame_id);
    AppendString(out, t.child_frame_id);
    for (double v : t.translation) AppendLe(out, v);
    for (double v : t.rotation) AppendLe(out, v);
  }
}

}  // namespace tiltcal::ros1
