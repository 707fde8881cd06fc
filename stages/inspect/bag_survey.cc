#include "stages/inspect/bag_survey.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "bag/ros1/bag_reader.h"
#include "bag/ros1/messages.h"

namespace tiltcal::inspect {
namespace {

std::string Join(const std::vector<std::string>& items) {
  if (items.empty()) return "none";
  return fmt::format("{}", fmt::join(items, ", "));
}

// The topic of message type `type`: the requested one, else the only one.
std::string ChooseTopic(const ros1::BagReader& reader, const std::string& type,
                        const std::string& requested, std::string* problem) {
  const std::vector<std::string> candidates = reader.TopicsOfType(type);
  if (!requested.empty()) {
    const std::string actual = reader.TopicType(requested);
    if (actual == type) return requested;
    *problem = actual.empty() ? fmt::format("no topic '{}' (named in the rig); {} topics: {}",
                                            requested, type, Join(candidates))
                              : fmt::format("topic '{}' (named in the rig) is {}, not {}",
                                            requested, actual, type);
    return "";
  }
  if (candidates.size() == 1) return candidates[0];
  *problem =
      candidates.empty()
          ? fmt::format("no {} topic in the bag (topics: {})", type, Join(reader.Topics()))
          : fmt::format("several {} topics ({}): name one in the rig", type, Join(candidates));
  return "";
}

class SurveySink {
 public:
  SurveySink(const BagSurveyOptions& options, int64_t num_scans, BagSurvey* survey)
      : options_(options), num_scans_(num_scans), survey_(survey) {}

  Status Add(const ros1::MessageView& m) {
    return m.connection->topic == survey_->imu_topic ? AddImu(m) : AddScan(m);
  }

 private:
  Status AddImu(const ros1::MessageView& m) {
    const Status decoded = ros1::DecodeImu(m.data, m.size, &imu_);
    if (!decoded.ok()) return MessageError(m, survey_->imu_stamp_ns.size(), decoded);
    survey_->imu_stamp_ns.push_back(ros1::RosTimeToNs(imu_.header.stamp));
    survey_->imu_record_ns.push_back(m.time_ns);
    survey_->gyro.emplace_back(imu_.angular_velocity[0], imu_.angular_velocity[1],
                               imu_.angular_velocity[2]);
    survey_->accel.emplace_back(imu_.linear_acceleration[0], imu_.linear_acceleration[1],
                                imu_.linear_acceleration[2]);
    return Status::Ok();
  }

  Status AddScan(const ros1::MessageView& m) {
    const size_t index = survey_->scan_stamp_ns.size();
    const Status decoded = ros1::DecodePointCloud2(m.data, m.size, &cloud_);
    if (!decoded.ok()) return MessageError(m, index, decoded);
    survey_->scan_stamp_ns.push_back(ros1::RosTimeToNs(cloud_.header.stamp));
    survey_->scan_record_ns.push_back(m.time_ns);
    survey_->scan_num_points.push_back(static_cast<int64_t>(cloud_.width) * cloud_.height);
    if (index == 0) survey_->layout = DescribeCloudLayout(cloud_);
    // Scan k·num_scans/max_sampled for k = 0, 1, ...: evenly spread.
    const int64_t next = static_cast<int64_t>(survey_->sampled_scans.size()) * num_scans_ /
                         static_cast<int64_t>(options_.max_sampled_scans);
    if (static_cast<int64_t>(index) < next ||
        survey_->sampled_scans.size() >= options_.max_sampled_scans) {
      return Status::Ok();
    }
    CloudSample sample;
    const Status sampled = SampleCloud(cloud_, options_.point_stride, &sample);
    if (!sampled.ok()) return MessageError(m, index, sampled);
    survey_->sampled_scans.push_back(std::move(sample));
    return Status::Ok();
  }

  Status MessageError(const ros1::MessageView& m, size_t index, const Status& what) const {
    return Status::Error(fmt::format("{}: topic '{}' message {}: {}", survey_->path,
                                     m.connection->topic, index, what.message()));
  }

  const BagSurveyOptions& options_;
  const int64_t num_scans_;
  BagSurvey* survey_;
  ros1::ImuMessage imu_;
  ros1::PointCloud2View cloud_;
};

}  // namespace

Status SurveyBag(const std::string& path, const BagSurveyOptions& options, BagSurvey* survey) {
  *survey = BagSurvey();
  survey->path = path;
  ros1::BagReader reader;
  TILTCAL_RETURN_IF_ERROR(reader.Open(path));
  survey->file_size = reader.file_size();
  survey->indexed = reader.indexed();
  survey->topics = reader.Topics();
  survey->imu_topic = ChooseTopic(reader, ros1::kImuType, options.imu_topic, &survey->imu_problem);
  survey->lidar_topic =
      ChooseTopic(reader, ros1::kPointCloud2Type, options.lidar_topic, &survey->lidar_problem);
  ros1::ReadOptions read;
  for (const std::string* topic : {&survey->imu_topic, &survey->lidar_topic}) {
    if (!topic->empty()) read.topics.push_back(*topic);
  }
  if (read.topics.empty()) return Status::Ok();
  const int64_t num_scans =
      survey->lidar_topic.empty() ? 0 : reader.MessageCount(survey->lidar_topic);
  SurveySink sink(options, num_scans, survey);
  return reader.ReadMessages(read, [&](const ros1::MessageView& m) { return sink.Add(m); });
}

}  // namespace tiltcal::inspect
