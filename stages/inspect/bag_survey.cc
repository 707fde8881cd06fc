#include "stages/inspect/bag_survey.h"

#include <algorithm>
#include <memory>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "bag/input/bag_input.h"
#include "bag/ros1/messages.h"
#include "bag/ros2/messages.h"

namespace tiltcal::inspect {
namespace {

std::string Join(const std::vector<std::string>& items) {
  if (items.empty()) return "none";
  return fmt::format("{}", fmt::join(items, ", "));
}

// The topic of one of the message types `types`: the requested one, else
// the only one.
std::string ChooseTopic(const bag::MessageReader& reader, const std::vector<std::string>& types,
                        const std::string& requested, std::string* problem) {
  std::vector<std::string> candidates;
  for (const std::string& type : types) {
    for (const std::string& topic : reader.TopicsOfType(type)) candidates.push_back(topic);
  }
  std::sort(candidates.begin(), candidates.end());
  const std::string type_names = fmt::format("{}", fmt::join(types, " or "));
  if (!requested.empty()) {
    const std::string actual = reader.TopicType(requested);
    if (std::find(types.begin(), types.end(), actual) != types.end()) return requested;
    *problem = actual.empty() ? fmt::format("no topic '{}' (named in the rig); {} topics: {}",
                                            requested, type_names, Join(candidates))
                              : fmt::format("topic '{}' (named in the rig) is {}, not {}",
                                            requested, actual, type_names);
    return "";
  }
  if (candidates.size() == 1) return candidates[0];
  *problem = candidates.empty() ? fmt::format("no {} topic in the bag (topics: {})", type_names,
                                              Join(reader.TopicNames()))
                                : fmt::format("several {} topics ({}): name one in the rig",
                                              type_names, Join(candidates));
  return "";
}

class SurveySink {
 public:
  SurveySink(const BagSurveyOptions& options, const bag::SensorTypes& types,
             const std::string& lidar_type, int64_t num_scans, BagSurvey* survey)
      : options_(options),
        point_cloud2_(lidar_type == types.point_cloud2),
        num_scans_(num_scans),
        survey_(survey) {}

  Status Add(const bag::Message& m) {
    return *m.topic == survey_->imu_topic ? AddImu(m) : AddScan(m);
  }

 private:
  static bool Cdr(const bag::Message& m) { return m.encoding == bag::Encoding::kCdr; }

  Status AddImu(const bag::Message& m) {
    const Status decoded = Cdr(m) ? ros2::DecodeImu(m.data, m.size, &imu_)
                                  : ros1::DecodeImu(m.data, m.size, &imu_);
    if (!decoded.ok()) return MessageError(m, survey_->imu_stamp_ns.size(), decoded);
    survey_->imu_stamp_ns.push_back(bag::RosTimeToNs(imu_.header.stamp));
    survey_->imu_record_ns.push_back(m.time_ns);
    survey_->gyro.emplace_back(imu_.angular_velocity[0], imu_.angular_velocity[1],
                               imu_.angular_velocity[2]);
    survey_->accel.emplace_back(imu_.linear_acceleration[0], imu_.linear_acceleration[1],
                                imu_.linear_acceleration[2]);
    return Status::Ok();
  }

  Status AddScan(const bag::Message& m) {
    const size_t index = survey_->scan_stamp_ns.size();
    const Status decoded =
        point_cloud2_ ? (Cdr(m) ? ros2::DecodePointCloud2(m.data, m.size, &cloud_)
                                : ros1::DecodePointCloud2(m.data, m.size, &cloud_))
                      : (Cdr(m) ? ros2::DecodeLivoxCustomMsg(m.data, m.size, &livox_)
                                : ros1::DecodeLivoxCustomMsg(m.data, m.size, &livox_));
    if (!decoded.ok()) return MessageError(m, index, decoded);
    const bag::Header& header = point_cloud2_ ? cloud_.header : livox_.header;
    survey_->scan_stamp_ns.push_back(bag::RosTimeToNs(header.stamp));
    survey_->scan_record_ns.push_back(m.time_ns);
    survey_->scan_num_points.push_back(
        point_cloud2_ ? static_cast<int64_t>(cloud_.width) * cloud_.height
                      : static_cast<int64_t>(livox_.points.size()));
    if (index == 0) {
      survey_->layout = point_cloud2_ ? DescribeCloudLayout(cloud_) : DescribeLivoxLayout();
    }
    // Scan k·num_scans/max_sampled for k = 0, 1, ...: evenly spread.
    const int64_t next = static_cast<int64_t>(survey_->sampled_scans.size()) * num_scans_ /
                         static_cast<int64_t>(options_.max_sampled_scans);
    if (static_cast<int64_t>(index) < next ||
        survey_->sampled_scans.size() >= options_.max_sampled_scans) {
      return Status::Ok();
    }
    CloudSample sample;
    if (point_cloud2_) {
      const Status sampled = SampleCloud(cloud_, options_.point_stride, &sample);
      if (!sampled.ok()) return MessageError(m, index, sampled);
    } else {
      SampleLivox(livox_, options_.point_stride, &sample);
    }
    survey_->sampled_scans.push_back(std::move(sample));
    return Status::Ok();
  }

  Status MessageError(const bag::Message& m, size_t index, const Status& what) const {
    return Status::Error(fmt::format("{}: topic '{}' message {} ({}): {}", survey_->path,
                                     *m.topic, index, bag::DescribePosition(m), what.message()));
  }

  const BagSurveyOptions& options_;
  const bool point_cloud2_;  // else a Livox CustomMsg
  const int64_t num_scans_;
  BagSurvey* survey_;
  bag::ImuMessage imu_;
  bag::PointCloud2View cloud_;
  bag::LivoxCustomMessage livox_;
};

}  // namespace

Status SurveyBag(const std::string& path, const BagSurveyOptions& options, BagSurvey* survey) {
  *survey = BagSurvey();
  survey->path = path;
  std::unique_ptr<bag::MessageReader> reader;
  TILTCAL_RETURN_IF_ERROR(bag::OpenBagInput(path, bag::Ros1ChunkSettings(), &reader));
  survey->format = reader->format_name();
  survey->file_size = reader->size_bytes();
  survey->indexed = reader->indexed();
  survey->topics = reader->TopicNames();
  const bag::SensorTypes types = bag::SensorTypesOf(*reader);
  survey->imu_topic =
      ChooseTopic(*reader, {types.imu}, options.imu_topic, &survey->imu_problem);
  survey->lidar_topic =
      ChooseTopic(*reader, types.Lidar(), options.lidar_topic, &survey->lidar_problem);
  if (!survey->imu_topic.empty() && survey->imu_topic == survey->lidar_topic) {
    survey->lidar_problem = "the IMU and the LiDAR topic are the same: " + survey->imu_topic;
    survey->lidar_topic.clear();
  }
  TILTCAL_RETURN_IF_ERROR(bag::ReadStaticTransforms(*reader, survey->imu_topic,
                                                    survey->lidar_topic, &survey->tf_static));
  bag::MessageSelection read;
  for (const std::string* topic : {&survey->imu_topic, &survey->lidar_topic}) {
    if (!topic->empty()) read.topics.push_back(*topic);
  }
  if (read.topics.empty()) return Status::Ok();
  const int64_t num_scans =
      survey->lidar_topic.empty() ? 0 : reader->MessageCount(survey->lidar_topic);
  SurveySink sink(options, types, reader->TopicType(survey->lidar_topic), num_scans, survey);
  return reader->ReadMessages(read, [&](const bag::Message& m) { return sink.Add(m); });
}

}  // namespace tiltcal::inspect
