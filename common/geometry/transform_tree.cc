#include "common/geometry/transform_tree.h"

#include <deque>
#include <map>

namespace tiltcal::geometry {

std::string NormalizeFrameId(const std::string& frame_id) {
  const size_t start = frame_id.find_first_not_of('/');
  return start == std::string::npos ? std::string() : frame_id.substr(start);
}

bool FindFrameChain(const std::vector<FrameEdge>& edges, const std::string& target,
                    const std::string& source, FrameChain* chain) {
  const std::string from = NormalizeFrameId(target);
  const std::string to = NormalizeFrameId(source);
  if (from.empty() || to.empty()) return false;
  // Neighbours of every frame: (edge index, walked from parent to child).
  std::map<std::string, std::vector<std::pair<size_t, bool>>> neighbours;
  for (size_t i = 0; i < edges.size(); ++i) {
    neighbours[NormalizeFrameId(edges[i].parent)].push_back({i, true});
    neighbours[NormalizeFrameId(edges[i].child)].push_back({i, false});
  }
  // Breadth first from the target; `reached_by` is the step into each frame.
  struct Step {
    std::string previous;
    size_t edge;
    bool parent_to_child;
  };
  std::map<std::string, Step> reached_by;
  reached_by[from] = {"", 0, false};
  std::deque<std::string> queue = {from};
  while (!queue.empty() && reached_by.count(to) == 0) {
    const std::string frame = queue.front();
    queue.pop_front();
    for (const auto& [index, parent_to_child] : neighbours[frame]) {
      const FrameEdge& e = edges[index];
      const std::string next = NormalizeFrameId(parent_to_child ? e.child : e.parent);
      if (next.empty() || reached_by.count(next) != 0) continue;
      reached_by[next] = {frame, index, parent_to_child};
      queue.push_back(next);
    }
  }
  if (reached_by.count(to) == 0) return false;
  // Walk back from the source: T_target←source = T_target←f1 · … · T_fn←source,
  // built right to left as T ← T_prev←frame · T.
  FrameChain result;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  std::vector<std::string> frames = {to};
  for (std::string frame = to; frame != from;) {
    const Step& step = reached_by.at(frame);
    const FrameEdge& e = edges[step.edge];
    // T_previous←frame: the edge as given when previous is the parent,
    // inverted when previous is the child.
    Eigen::Quaterniond q = e.parent_from_child_rotation;
    Eigen::Vector3d t = e.parent_from_child_translation;
    if (!step.parent_to_child) {
      q = q.conjugate();
      t = -(q * e.parent_from_child_translation);
    }
    translation = q * translation + t;
    rotation = q * rotation;
    frame = step.previous;
    frames.push_back(frame);
  }
  result.frames.assign(frames.rbegin(), frames.rend());
  result.target_from_source_rotation = rotation.normalized();
  result.target_from_source_translation = translation;
  *chain = result;
  return true;
}

}  // namespace tiltcal::geometry
