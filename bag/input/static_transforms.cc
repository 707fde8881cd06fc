#include "bag/input/static_transforms.h"

#include <cmath>
#include <map>

#include <fmt/format.h>

#include "bag/ros1/messages.h"
#include "bag/ros2/messages.h"
#include "common/geometry/angles.h"
#include "common/geometry/euler_angles.h"
#include "common/io/eigen_proto.h"

namespace tiltcal::bag {

namespace {

// The status that ends the read once every message needed is in.
constexpr char kEverythingRead[] = "static transforms: every message needed is read";

bool IsTfType(const std::string& type) {
  return type == ros1::kTfMessageType || type == ros1::kTfLegacyMessageType ||
         type == ros2::kTfMessageType;
}

std::string Context(const MessageReader& reader, const Message& m, int64_t index) {
  return fmt::format("{}: topic '{}' message {} ({})", reader.path(), *m.topic, index,
                     DescribePosition(m));
}

// The header.frame_id of a sensor message of type `type`.
Status FrameIdOf(const Message& m, const std::string& type, std::string* frame_id) {
  const bool cdr = m.encoding == Encoding::kCdr;
  if (type == ros1::kImuType || type == ros2::kImuType) {
    ImuMessage imu;
    TILTCAL_RETURN_IF_ERROR(cdr ? ros2::DecodeImu(m.data, m.size, &imu)
                                : ros1::DecodeImu(m.data, m.size, &imu));
    *frame_id = imu.header.frame_id;
  } else if (type == ros1::kPointCloud2Type || type == ros2::kPointCloud2Type) {
    PointCloud2View cloud;
    TILTCAL_RETURN_IF_ERROR(cdr ? ros2::DecodePointCloud2(m.data, m.size, &cloud)
                                : ros1::DecodePointCloud2(m.data, m.size, &cloud));
    *frame_id = cloud.header.frame_id;
  } else {
    LivoxCustomMessage livox;
    TILTCAL_RETURN_IF_ERROR(cdr ? ros2::DecodeLivoxCustomMsg(m.data, m.size, &livox)
                                : ros1::DecodeLivoxCustomMsg(m.data, m.size, &livox));
    *frame_id = livox.header.frame_id;
  }
  return Status::Ok();
}

// The transform as an edge; "" when valid, else why it is skipped.
std::string ToEdge(const TransformStamped& t, geometry::FrameEdge* edge) {
  edge->parent = geometry::NormalizeFrameId(t.header.frame_id);
  edge->child = geometry::NormalizeFrameId(t.child_frame_id);
  if (edge->parent.empty() || edge->child.empty()) return "an empty frame id";
  if (edge->parent == edge->child) return "its parent and child are one frame";
  const Eigen::Vector3d translation(t.translation[0], t.translation[1], t.translation[2]);
  // Eigen's constructor takes (w, x, y, z); the wire order is x, y, z, w.
  const Eigen::Quaterniond rotation(t.rotation[3], t.rotation[0], t.rotation[1], t.rotation[2]);
  if (!translation.allFinite() || !rotation.coeffs().allFinite()) return "a value that is not finite";
  if (std::abs(rotation.norm() - 1.0) > 1e-3) {
    return fmt::format("a quaternion of norm {:.6g}", rotation.norm());
  }
  edge->parent_from_child_rotation = rotation.normalized();
  edge->parent_from_child_translation = translation;
  return "";
}

bool SameTransform(const geometry::FrameEdge& a, const geometry::FrameEdge& b) {
  return a.parent == b.parent &&
         a.parent_from_child_rotation.coeffs() == b.parent_from_child_rotation.coeffs() &&
         a.parent_from_child_translation == b.parent_from_child_translation;
}

// Adds the transforms of one message: a child published again replaces its
// transform (tf2's rule for static transforms).
void AddTransforms(const TfMessage& msg, int64_t index, std::map<std::string, size_t>* by_child,
                   StaticTransforms* out) {
  auto warn = [&](const std::string& warning) {
    for (const std::string& w : out->warnings) {
      if (w == warning) return;
    }
    out->warnings.push_back(warning);
  };
  for (const TransformStamped& t : msg.transforms) {
    ++out->num_transforms;
    geometry::FrameEdge edge;
    const std::string problem = ToEdge(t, &edge);
    if (!problem.empty()) {
      warn(fmt::format("transform '{}' -> '{}' in message {} skipped: {}",
                       t.header.frame_id, t.child_frame_id, index, problem));
      continue;
    }
    const auto [it, inserted] = by_child->emplace(edge.child, out->edges.size());
    if (inserted) {
      out->edges.push_back(edge);
      continue;
    }
    geometry::FrameEdge& known = out->edges[it->second];
    if (!SameTransform(known, edge)) {
      warn(fmt::format("frame '{}' is published again with another transform "
                       "(parent '{}', was '{}'); the last one is used, as tf2 does",
                       edge.child, edge.parent, known.parent));
      known = edge;
    }
  }
}

std::string ChainText(const std::vector<std::string>& frames) {
  std::string text;
  for (const std::string& f : frames) text += (text.empty() ? "" : " <- ") + f;
  return text;
}

void Summarise(StaticTransforms* s) {
  const std::string imu = geometry::NormalizeFrameId(s->imu_frame_id);
  const std::string lidar = geometry::NormalizeFrameId(s->lidar_frame_id);
  if (imu.empty() || lidar.empty()) {
    s->summary = fmt::format(
        "the {} frame is unknown (no message, or an empty frame_id): tf_static cannot place it",
        imu.empty() ? "IMU" : "LiDAR");
    return;
  }
  if (imu == lidar) {
    s->summary = fmt::format(
        "the IMU and the LiDAR messages are both in frame '{}': tf_static gives no extrinsic",
        imu);
    return;
  }
  if (s->tf_topic.empty()) {
    s->summary = fmt::format("no /tf_static in the bag: no tf_static transform joins '{}' and "
                             "'{}'",
                             imu, lidar);
    return;
  }
  s->found = geometry::FindFrameChain(s->edges, imu, lidar, &s->imu_from_lidar);
  if (!s->found) {
    s->summary = fmt::format("no tf_static transform joins '{}' and '{}' ({} transforms in {} "
                             "messages on {})",
                             imu, lidar, s->edges.size(), s->num_messages, s->tf_topic);
    return;
  }
  const geometry::FrameChain& c = s->imu_from_lidar;
  Eigen::Quaterniond q = c.target_from_source_rotation;
  if (q.w() < 0) q.coeffs() = -q.coeffs();  // as written to the provenance
  const Eigen::Vector3d euler_deg =
      geometry::Euler123FromRotation(q.toRotationMatrix()) * geometry::kDegPerRad;
  const Eigen::Vector3d& r = c.target_from_source_translation;
  s->summary = fmt::format(
      "imu_from_lidar along {}: rotation (w x y z) {:.6f} {:.6f} {:.6f} {:.6f} "
      "(Euler 1-2-3 {:.3f} {:.3f} {:.3f} deg), translation {:.4f} {:.4f} {:.4f} m",
      ChainText(c.frames), q.w(), q.x(), q.y(), q.z(), euler_deg.x(), euler_deg.y(),
      euler_deg.z(), r.x(), r.y(), r.z());
}

}  // namespace

Status ReadStaticTransforms(MessageReader& reader, const std::string& imu_topic,
                            const std::string& lidar_topic, StaticTransforms* result) {
  StaticTransforms s;
  for (const char* name : {kTfStaticTopic, kTfStaticTopic + 1}) {
    const std::string type = reader.TopicType(name);
    if (type.empty()) continue;
    if (IsTfType(type)) {
      s.tf_topic = name;
      break;
    }
    s.warnings.push_back(fmt::format("topic '{}' has type {}, not a TFMessage: not read", name,
                                     type));
  }
  const std::string imu_type = reader.TopicType(imu_topic);
  const std::string lidar_type = reader.TopicType(lidar_topic);
  const int64_t tf_count = s.tf_topic.empty() ? 0 : reader.MessageCount(s.tf_topic);
  bool need_imu = !imu_type.empty() && reader.MessageCount(imu_topic) > 0;
  bool need_lidar = !lidar_type.empty() && reader.MessageCount(lidar_topic) > 0;
  MessageSelection selection;
  if (!s.tf_topic.empty()) selection.topics.push_back(s.tf_topic);
  if (need_imu) selection.topics.push_back(imu_topic);
  if (need_lidar) selection.topics.push_back(lidar_topic);
  if (!selection.topics.empty()) {
    std::map<std::string, size_t> by_child;
    TfMessage tf;
    const Status read = reader.ReadMessages(selection, [&](const Message& m) -> Status {
      if (*m.topic == s.tf_topic) {
        const Status decoded = m.encoding == Encoding::kCdr
                                   ? ros2::DecodeTfMessage(m.data, m.size, &tf)
                                   : ros1::DecodeTfMessage(m.data, m.size, &tf);
        if (!decoded.ok()) return decoded.WithContext(Context(reader, m, s.num_messages));
        AddTransforms(tf, s.num_messages++, &by_child, &s);
      } else if (need_imu && *m.topic == imu_topic) {
        TILTCAL_RETURN_IF_ERROR(
            FrameIdOf(m, imu_type, &s.imu_frame_id).WithContext(Context(reader, m, 0)));
        need_imu = false;
      } else if (need_lidar && *m.topic == lidar_topic) {
        TILTCAL_RETURN_IF_ERROR(
            FrameIdOf(m, lidar_type, &s.lidar_frame_id).WithContext(Context(reader, m, 0)));
        need_lidar = false;
      }
      if (!need_imu && !need_lidar && s.num_messages >= tf_count) {
        return Status::Error(kEverythingRead);
      }
      return Status::Ok();
    });
    if (!read.ok() && read.message() != kEverythingRead) return read;
  }
  Summarise(&s);
  *result = std::move(s);
  return Status::Ok();
}

proto::TfStaticExtrinsic ToProto(const StaticTransforms& transforms) {
  proto::TfStaticExtrinsic out;
  out.set_imu_frame_id(transforms.imu_frame_id);
  out.set_lidar_frame_id(transforms.lidar_frame_id);
  if (transforms.found) {
    const geometry::FrameChain& c = transforms.imu_from_lidar;
    Eigen::Quaterniond q = c.target_from_source_rotation;
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    *out.mutable_imu_from_lidar() = tiltcal::ToProto(Rigid3d{q, c.target_from_source_translation});
    for (const std::string& frame : c.frames) out.add_chain(frame);
  }
  out.set_num_messages(transforms.num_messages);
  out.set_num_transforms(transforms.num_transforms);
  out.set_summary(transforms.summary);
  return out;
}

}  // namespace tiltcal::bag
