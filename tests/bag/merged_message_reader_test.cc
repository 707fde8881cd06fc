// MergedMessageReader over in-memory readers: record-time order with ties in
// file order, topics and counts across files, topic selection and time
// window, duplicates given once, errors named and stopping every file, and
// files started only when the merge reaches them.
#include "bag/merged_message_reader.h"

#include <algorithm>
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace tiltcal::bag {
namespace {

struct FakeMessage {
  std::string topic;
  int64_t time_ns;
  std::string bytes;
};

// A file of messages in record-time order; `fail_at` >= 0 makes reading
// fail at that message.
class FakeReader : public MessageReader {
 public:
  FakeReader(std::string path, std::vector<TopicInfo> topics, std::vector<FakeMessage> messages,
             int fail_at = -1)
      : path_(std::move(path)), topics_(std::move(topics)), messages_(std::move(messages)),
        fail_at_(fail_at) {
    for (TopicInfo& t : topics_) {
      for (const FakeMessage& m : messages_) t.message_count += m.topic == t.name;
    }
  }

  const std::string& path() const override { return path_; }
  uint64_t size_bytes() const override { return 100; }
  std::string format_name() const override { return "fake"; }
  bool indexed() const override { return true; }
  const std::vector<TopicInfo>& topics() const override { return topics_; }
  bool TimeRange(int64_t* start_ns, int64_t* end_ns) const override {
    if (messages_.empty()) return false;
    *start_ns = messages_.front().time_ns;
    *end_ns = messages_.back().time_ns;
    return true;
  }
  Status ReadMessages(const MessageSelection& selection,
                      const std::function<Status(const Message&)>& fn) override {
    started = true;
    Message out;
    out.position_name = "message";
    for (size_t i = 0; i < messages_.size(); ++i) {
      const FakeMessage& m = messages_[i];
      if (static_cast<int>(i) == fail_at_) {
        return Status::Error(path_ + ": message " + std::to_string(i) + " is broken");
      }
      if (m.time_ns < selection.start_ns || m.time_ns >= selection.end_ns) continue;
      if (!selection.topics.empty() &&
          std::find(selection.topics.begin(), selection.topics.end(), m.topic) ==
              selection.topics.end()) {
        continue;
      }
      for (const TopicInfo& t : topics_) {
        if (t.name == m.topic) out.topic = &t.name;
      }
      out.time_ns = m.time_ns;
      out.position = i;
      out.data = reinterpret_cast<const uint8_t*>(m.bytes.data());
      out.size = m.bytes.size();
      TILTCAL_RETURN_IF_ERROR(fn(out));
    }
    return Status::Ok();
  }

  std::atomic<bool> started{false};

 private:
  std::string path_;
  std::vector<TopicInfo> topics_;
  std::vector<FakeMessage> messages_;
  int fail_at_;
};

const std::vector<TopicInfo> kImuAndLidar = {{"/imu", "sensor_msgs/Imu", 0},
                                             {"/lidar", "sensor_msgs/PointCloud2", 0}};

// "topic time bytes file position" per message given.
std::vector<std::string> ReadAll(MergedMessageReader* reader, const MessageSelection& selection,
                                 Status* status) {
  std::vector<std::string> out;
  *status = reader->ReadMessages(selection, [&](const Message& m) {
    EXPECT_EQ(m.sequence, out.size());
    out.push_back(*m.topic + " " + std::to_string(m.time_ns) + " " +
                  std::string(reinterpret_cast<const char*>(m.data), m.size) + " " +
                  DescribePosition(m));
    return Status::Ok();
  });
  return out;
}

TEST(MergedMessageReader, MergesInRecordTimeWithTiesInFileOrder) {
  std::vector<std::unique_ptr<MessageReader>> files;
  files.push_back(std::make_unique<FakeReader>(
      "run/imu.bag", std::vector<TopicInfo>{kImuAndLidar[0]},
      std::vector<FakeMessage>{{"/imu", 10, "i10"}, {"/imu", 20, "i20"}, {"/imu", 30, "i30"}}));
  files.push_back(std::make_unique<FakeReader>(
      "run/lidar.bag", std::vector<TopicInfo>{kImuAndLidar[1]},
      std::vector<FakeMessage>{{"/lidar", 5, "l5"}, {"/lidar", 20, "l20"}, {"/lidar", 35, "l35"}}));
  MergedMessageReader reader;
  ASSERT_TRUE(reader.Open("run", std::move(files)).ok());
  EXPECT_EQ(reader.TopicNames(), (std::vector<std::string>{"/imu", "/lidar"}));
  EXPECT_EQ(reader.MessageCount("/imu"), 3);
  EXPECT_EQ(reader.MessageCount("/lidar"), 3);
  EXPECT_EQ(reader.input_files(), (std::vector<std::string>{"run/imu.bag", "run/lidar.bag"}));
  EXPECT_EQ(reader.format_name(), "2 files (fake)");
  int64_t start = 0, end = 0;
  ASSERT_TRUE(reader.TimeRange(&start, &end));
  EXPECT_EQ(start, 5);
  EXPECT_EQ(end, 35);
  Status status;
  EXPECT_EQ(ReadAll(&reader, {}, &status),
            (std::vector<std::string>{
                "/lidar 5 l5 message 0 in run/lidar.bag", "/imu 10 i10 message 0 in run/imu.bag",
                "/imu 20 i20 message 1 in run/imu.bag", "/lidar 20 l20 message 1 in run/lidar.bag",
                "/imu 30 i30 message 2 in run/imu.bag",
                "/lidar 35 l35 message 2 in run/lidar.bag"}));
  EXPECT_TRUE(status.ok()) << status.message();
  // One topic, inside [10, 30): the other file is not read at all.
  MessageSelection selection;
  selection.topics = {"/imu"};
  selection.start_ns = 10;
  selection.end_ns = 30;
  EXPECT_EQ(ReadAll(&reader, selection, &status),
            (std::vector<std::string>{"/imu 10 i10 message 0 in run/imu.bag",
                                      "/imu 20 i20 message 1 in run/imu.bag"}));
  EXPECT_TRUE(status.ok()) << status.message();
}

TEST(MergedMessageReader, SameMessageInTwoOverlappingFilesIsGivenOnce) {
  std::vector<std::unique_ptr<MessageReader>> files;
  files.push_back(std::make_unique<FakeReader>(
      "run/run_0.bag", kImuAndLidar,
      std::vector<FakeMessage>{{"/imu", 10, "a"}, {"/lidar", 15, "s"}, {"/imu", 20, "b"}}));
  // Overlaps the first file by one message of each topic; a different
  // /imu message at time 20 is kept (only equal bytes are a duplicate).
  files.push_back(std::make_unique<FakeReader>(
      "run/run_1.bag", kImuAndLidar,
      std::vector<FakeMessage>{
          {"/lidar", 15, "s"}, {"/imu", 20, "b"}, {"/imu", 20, "B"}, {"/imu", 30, "c"}}));
  MergedMessageReader reader;
  ASSERT_TRUE(reader.Open("run", std::move(files)).ok());
  EXPECT_EQ(reader.MessageCount("/imu"), 5);  // as stored in the files
  Status status;
  EXPECT_EQ(ReadAll(&reader, {}, &status),
            (std::vector<std::string>{
                "/imu 10 a message 0 in run/run_0.bag", "/lidar 15 s message 1 in run/run_0.bag",
                "/imu 20 b message 2 in run/run_0.bag", "/imu 20 B message 2 in run/run_1.bag",
                "/imu 30 c message 3 in run/run_1.bag"}));
  EXPECT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(reader.duplicates_dropped(), 2);
}

TEST(MergedMessageReader, FilesAreReadOnlyWhenTheMergeReachesThem) {
  // Three time-split files of 3000 messages each (more than a file may
  // read ahead): a later file starts only once the merge has reached its
  // first record time.
  std::vector<FakeReader*> raw;
  std::vector<std::unique_ptr<MessageReader>> files;
  for (int f = 0; f < 3; ++f) {
    std::vector<FakeMessage> messages;
    for (int i = 0; i < 3000; ++i) messages.push_back({"/imu", f * 10000 + i, "x"});
    auto file = std::make_unique<FakeReader>("run/run_" + std::to_string(f) + ".bag",
                                             std::vector<TopicInfo>{kImuAndLidar[0]}, messages);
    raw.push_back(file.get());
    files.push_back(std::move(file));
  }
  MergedMessageReader reader;
  ASSERT_TRUE(reader.Open("run", std::move(files)).ok());
  int64_t count = 0;
  const Status status = reader.ReadMessages({}, [&](const Message& m) {
    for (int f = 1; f < 3; ++f) {
      if (m.time_ns < f * 10000) {
        EXPECT_FALSE(raw[f]->started) << "file " << f << " at " << m.time_ns;
      }
    }
    ++count;
    return Status::Ok();
  });
  EXPECT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(count, 9000);
}

TEST(MergedMessageReader, ErrorsNameTheFileAndStopTheMerge) {
  auto make = [](int fail_at) {
    std::vector<FakeMessage> messages;
    for (int i = 0; i < 5000; ++i) messages.push_back({"/imu", 2 * i, "x"});
    std::vector<std::unique_ptr<MessageReader>> files;
    files.push_back(std::make_unique<FakeReader>(
        "run/a.bag", std::vector<TopicInfo>{kImuAndLidar[0]}, messages));
    for (FakeMessage& m : messages) ++m.time_ns;
    files.push_back(std::make_unique<FakeReader>(
        "run/b.bag", std::vector<TopicInfo>{kImuAndLidar[0]}, messages, fail_at));
    return files;
  };
  {
    MergedMessageReader reader;
    ASSERT_TRUE(reader.Open("run", make(2500)).ok());
    Status status;
    const std::vector<std::string> read = ReadAll(&reader, {}, &status);
    EXPECT_EQ(status.message(), "run/b.bag: message 2500 is broken");
    EXPECT_EQ(read.size(), 5000u);  // every message before the broken one
  }
  {
    // The consumer's error ends the merge with the reading threads joined.
    MergedMessageReader reader;
    ASSERT_TRUE(reader.Open("run", make(-1)).ok());
    int count = 0;
    const Status status = reader.ReadMessages({}, [&](const Message&) {
      return ++count == 100 ? Status::Error("enough") : Status::Ok();
    });
    EXPECT_EQ(status.message(), "enough");
  }
}

TEST(MergedMessageReader, TopicTypesMustAgreeAndRosVersionsMustNotMix) {
  {
    std::vector<std::unique_ptr<MessageReader>> files;
    files.push_back(std::make_unique<FakeReader>(
        "run/a.bag", std::vector<TopicInfo>{{"/imu", "sensor_msgs/Imu", 0}},
        std::vector<FakeMessage>{{"/imu", 1, "x"}}));
    files.push_back(std::make_unique<FakeReader>(
        "run/b.bag", std::vector<TopicInfo>{{"/imu", "sensor_msgs/MagneticField", 0}},
        std::vector<FakeMessage>{{"/imu", 2, "x"}}));
    MergedMessageReader reader;
    EXPECT_EQ(reader.Open("run", std::move(files)).message(),
              "run/b.bag: topic '/imu' has type sensor_msgs/MagneticField, but sensor_msgs/Imu "
              "in run/a.bag");
  }
  {
    std::vector<std::unique_ptr<MessageReader>> files;
    files.push_back(std::make_unique<FakeReader>(
        "run/imu.bag", std::vector<TopicInfo>{{"/imu", "sensor_msgs/Imu", 0}},
        std::vector<FakeMessage>{{"/imu", 1, "x"}}));
    files.push_back(std::make_unique<FakeReader>(
        "run/lidar.mcap", std::vector<TopicInfo>{{"/points", "sensor_msgs/msg/PointCloud2", 0}},
        std::vector<FakeMessage>{{"/points", 2, "x"}}));
    MergedMessageReader reader;
    const std::string message = reader.Open("run", std::move(files)).message();
    EXPECT_NE(message.find("run/imu.bag holds ROS 1 messages and run/lidar.mcap ROS 2 ones"),
              std::string::npos)
        << message;
  }
}

// An empty ROS 1 file after the one with messages does not hide the mix:
// the first file of each version that holds messages is named.
TEST(MergedMessageReader, RosVersionsMixIsFoundWhenTheLastRos1FileIsEmpty) {
  std::vector<std::unique_ptr<MessageReader>> files;
  files.push_back(std::make_unique<FakeReader>(
      "run/a_imu.bag", std::vector<TopicInfo>{{"/imu", "sensor_msgs/Imu", 0}},
      std::vector<FakeMessage>{{"/imu", 1, "x"}}));
  files.push_back(std::make_unique<FakeReader>(
      "run/b_lidar.mcap", std::vector<TopicInfo>{{"/points", "sensor_msgs/msg/PointCloud2", 0}},
      std::vector<FakeMessage>{{"/points", 2, "x"}}));
  files.push_back(std::make_unique<FakeReader>("run/c_empty.bag", std::vector<TopicInfo>{},
                                               std::vector<FakeMessage>{}));
  MergedMessageReader reader;
  const std::string message = reader.Open("run", std::move(files)).message();
  EXPECT_NE(message.find("run/a_imu.bag holds ROS 1 messages and run/b_lidar.mcap ROS 2 ones"),
            std::string::npos)
      << message;
}

// The warnings of every file, in file order.
TEST(MergedMessageReader, WarningsOfEveryFile) {
  class Warns : public FakeReader {
   public:
    Warns(std::string path, std::string warning)
        : FakeReader(std::move(path), kImuAndLidar, {{"/imu", 1, "x"}}),
          warning_(std::move(warning)) {}
    std::vector<std::string> warnings() const override { return {warning_}; }

   private:
    std::string warning_;
  };
  std::vector<std::unique_ptr<MessageReader>> files;
  files.push_back(std::make_unique<Warns>("run/a.bag", "run/a.bag: one"));
  files.push_back(std::make_unique<Warns>("run/b.bag", "run/b.bag: two"));
  MergedMessageReader reader;
  ASSERT_TRUE(reader.Open("run", std::move(files)).ok());
  EXPECT_EQ(reader.warnings(), (std::vector<std::string>{"run/a.bag: one", "run/b.bag: two"}));
}

}  // namespace
}  // namespace tiltcal::bag
