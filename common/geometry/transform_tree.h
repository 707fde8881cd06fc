#ifndef TILTCAL_COMMON_GEOMETRY_TRANSFORM_TREE_H_
#define TILTCAL_COMMON_GEOMETRY_TRANSFORM_TREE_H_

// A tree of named frames joined by rigid transforms (the static transforms a
// robot publishes on /tf_static, its URDF), and the transform between any
// two frames it joins. Each edge is the pose of `child` in `parent`:
//   p_parent = parent_from_child_rotation p_child + parent_from_child_translation.
// A path from frame `target` to frame `source` walks the edges in either
// direction; an edge walked from child to parent is used as it is, one
// walked from parent to child inverted, and
//   target_from_source = T_target←f1 · T_f1←f2 · … · T_fn←source.
// Frame names are compared without leading '/' ("/imu" and "imu" are one
// frame).

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tiltcal::geometry {

struct FrameEdge {
  std::string parent;
  std::string child;
  Eigen::Quaterniond parent_from_child_rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d parent_from_child_translation = Eigen::Vector3d::Zero();
};

struct FrameChain {
  // The frames from target to source, both included (names as normalised).
  std::vector<std::string> frames;
  // x_target = rotation x_source + translation (translation resolved in target).
  Eigen::Quaterniond target_from_source_rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d target_from_source_translation = Eigen::Vector3d::Zero();
};

// "imu" for "/imu", "//imu" and "imu".
std::string NormalizeFrameId(const std::string& frame_id);

// The shortest chain of edges joining `target` and `source` (breadth first,
// edges in the order given on ties), composed as above. False when no chain
// joins them or either name is empty. `target` == `source` is a chain of one
// frame and the identity. Edges must have unit quaternions.
bool FindFrameChain(const std::vector<FrameEdge>& edges, const std::string& target,
                    const std::string& source, FrameChain* chain);

}  // namespace tiltcal::geometry

#endif  // TILTCAL_COMMON_GEOMETRY_TRANSFORM_TREE_H_
