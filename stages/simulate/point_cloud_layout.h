#ifndef TILTCAL_STAGES_SIMULATE_POINT_CLOUD_LAYOUT_H_
#define TILTCAL_STAGES_SIMULATE_POINT_CLOUD_LAYOUT_H_

#include <cstdint>
#include <string>

#include "stages/simulate/scan_simulator.h"

namespace tiltcal::simulate {

// Serializes a simulated sweep as the sensor_msgs/PointCloud2 the real ROS1
// drivers publish (see reference bag-formats.md §5):
// - Velodyne (velodyne_pointcloud XYZIRT, unordered, height 1, dense):
//   x y z intensity FLOAT32 @0/4/8/12, ring UINT16 @16, time FLOAT32 @18
//   (s relative to the stamp), point_step 22;
// - Ouster (ouster_ros::Point, organized rows = beams, not dense, NaN xyz for
//   no return): x y z FLOAT32 @0/4/8, intensity FLOAT32 @16, t UINT32 @20
//   (ns since the stamp), reflectivity UINT16 @24, ring UINT16 @26,
//   ambient UINT16 @28, range UINT32 @32 (mm), point_step 48.
// With `append_label` a UINT8 field `label` (SurfaceLabel) is added: at @22
// (point_step 23) for Velodyne, in the padding at @30 for Ouster.
// `stamp_ns` is the bag stamp (LiDAR clock).
bool SerializeScan(const SimulatedScan& scan, bool ouster, bool append_label, uint32_t seq,
                   int64_t stamp_ns, const std::string& frame_id, std::string* message);

// Serializes a simulated Livox frame as livox_ros_driver/CustomMsg:
// header.stamp = timebase = `stamp_ns`, every point (no return at the
// origin), offset_time = ScanPoint::time_ns, reflectivity, tag, line = ring.
bool SerializeLivoxScan(const SimulatedScan& scan, uint32_t seq, int64_t stamp_ns,
                        const std::string& frame_id, std::string* message);

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_POINT_CLOUD_LAYOUT_H_
