// The MCAP reader against the official MCAP conformance data
// (../shared/fixtures/bags/mcap_conformance/, README beside it): every
// .mcap of the six cases, each written in every combination of the
// writer's options, read as its .json says. The reader's messages (channel
// topic, log time, publish time, sequence, data bytes) equal the json's
// Message records: in file order from the streaming read (the data section
// scanned), sorted by log time (ties in file order) from the read through
// the indexes, both where the file has them (`chx` and `mx` in its name).
// Schemaless channels, attachments and metadata records are no error. A
// file the reader cannot read fails the test.
//
// Where the suite holds Git LFS pointers instead of the files, the files
// are first written from their .json with the official MCAP library
// (tests/oracle/write_mcap_conformance.mjs), which checks each against the
// sha256 and size of its pointer: the files read are then the suite's own,
// byte for byte. Without the npm oracle that is a failure, not a skip.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bag/mcap/mcap_reader.h"
#include "tests/testing/json_value.h"
#include "tests/testing/test_env.h"

namespace tiltcal::mcap {
namespace {

namespace fs = std::filesystem;
using testing::JsonValue;

// One message as the comparison sees it.
struct ConformanceMessage {
  std::string topic;
  uint64_t log_time = 0;
  uint64_t publish_time = 0;
  uint32_t sequence = 0;
  std::vector<uint8_t> data;
  bool operator==(const ConformanceMessage& o) const {
    return topic == o.topic && log_time == o.log_time && publish_time == o.publish_time &&
           sequence == o.sequence && data == o.data;
  }
};

std::ostream& operator<<(std::ostream& out, const ConformanceMessage& m) {
  out << "{topic '" << m.topic << "' log_time " << m.log_time << " publish_time "
      << m.publish_time << " sequence " << m.sequence << " data [";
  for (size_t i = 0; i < m.data.size(); ++i) out << (i ? " " : "") << int{m.data[i]};
  return out << "]}";
}

std::string ConformanceDir() {
  const std::string fixtures = testing::SharedFixturesDir();
  if (fixtures.empty()) return "";
  const std::string dir = fixtures + "/bags/mcap_conformance";
  return fs::is_directory(dir) ? dir : "";
}

// The fields of one json record: name -> value.
std::map<std::string, const JsonValue*> Fields(const JsonValue& record) {
  std::map<std::string, const JsonValue*> fields;
  const JsonValue* list = record.Find("fields");
  if (list == nullptr) return fields;
  for (const JsonValue& pair : list->items) {
    if (pair.items.size() == 2) fields[pair.items[0].text] = &pair.items[1];
  }
  return fields;
}

// The Message records of `json_path` in file order, with their channels'
// topics; "" or what is wrong with the json.
std::string ExpectedMessages(const std::string& json_path,
                             std::vector<ConformanceMessage>* messages) {
  std::ifstream in(json_path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  JsonValue root;
  std::string error;
  if (!testing::ParseJson(text.str(), &root, &error)) return json_path + ": " + error;
  const JsonValue* records = root.Find("records");
  if (records == nullptr) return json_path + ": no records";
  std::map<std::string, std::string> topics;  // channel id -> topic
  for (const JsonValue& record : records->items) {
    const JsonValue* type = record.Find("type");
    if (type == nullptr) return json_path + ": a record without type";
    auto fields = Fields(record);
    if (type->text == "Channel") {
      topics[fields["id"]->text] = fields["topic"]->text;
    } else if (type->text == "Message") {
      ConformanceMessage m;
      const std::string channel = fields["channel_id"]->text;
      if (topics.count(channel) == 0) return json_path + ": message before its channel";
      m.topic = topics[channel];
      m.log_time = std::stoull(fields["log_time"]->text);
      m.publish_time = std::stoull(fields["publish_time"]->text);
      m.sequence = static_cast<uint32_t>(std::stoul(fields["sequence"]->text));
      for (const JsonValue& byte : fields["data"]->items) {
        m.data.push_back(static_cast<uint8_t>(std::stoul(byte.text)));
      }
      messages->push_back(std::move(m));
    }
  }
  return "";
}

// Opens `path` as `summary_use` says and reads its messages in `order`;
// "" or the reader's error.
std::string ReadWith(const std::string& path, McapReader::SummaryUse summary_use,
                     McapReader::Order order, bool* used_summary,
                     std::vector<ConformanceMessage>* messages) {
  McapReader reader;
  Status status = reader.Open(path, summary_use);
  if (!status.ok()) return status.message();
  *used_summary = reader.used_summary();
  status = reader.ReadMessageRecords(
      {}, order, [&](const bag::Message& m, const MessageRecord& record) {
        messages->push_back({*m.topic, record.log_time, record.publish_time, record.sequence,
                             std::vector<uint8_t>(m.data, m.data + m.size)});
        return Status::Ok();
      });
  return status.ok() ? "" : status.message();
}

// The .mcap files of one case folder, sorted.
std::vector<std::string> McapFilesOf(const std::string& case_dir) {
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(case_dir)) {
    if (entry.path().extension() == ".mcap") files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// The writer options a file name lists ("ch", "chx", "mx", "rch", ...).
bool HasOption(const std::string& mcap_path, const std::string& option) {
  const std::string name = fs::path(mcap_path).stem().string() + "-";
  return name.find("-" + option + "-") != std::string::npos;
}

bool IsLfsPointer(const std::string& path) {
  char head[8] = {};
  std::ifstream(path, std::ios::binary).read(head, sizeof(head));
  return std::string(head, sizeof(head)) == "version ";
}

class McapConformance : public ::testing::Test {
 protected:
  // The suite's .mcap files, written from their .json where the fixture
  // holds LFS pointers (once for every case).
  static void SetUpTestSuite() {
    const std::string dir = ConformanceDir();
    if (dir.empty()) return;
    read_dir_ = new std::string(dir);
    setup_error_ = new std::string();
    bool pointers = false;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
      if (entry.path().extension() == ".mcap") pointers = pointers || IsLfsPointer(entry.path());
    }
    if (!pointers) return;
    written_ = new testing::TempDir();
    *read_dir_ = written_->path();
    const std::string modules = testing::SourceDir() + "/tests/node_modules";
    if (!testing::FileExists(modules + "/@mcap/core/package.json") ||
        testing::RunCommand("node --version >/dev/null 2>&1") != 0) {
      *setup_error_ = dir + " holds Git LFS pointers and the npm oracle that writes the files "
                      "(node, " + modules + "; scripts/setup.sh) is missing";
      return;
    }
    std::string output;
    const std::string command = "cd " + testing::SourceDir() +
                                "/tests && node oracle/write_mcap_conformance.mjs " + dir + " " +
                                written_->path();
    if (testing::RunCommand(command, &output) != 0) *setup_error_ = command + ": " + output;
  }
  static void TearDownTestSuite() {
    delete written_;
    delete read_dir_;
    delete setup_error_;
    written_ = nullptr;
    read_dir_ = setup_error_ = nullptr;
  }
  static testing::TempDir* written_;
  static std::string* read_dir_;     // where the .mcap files are read
  static std::string* setup_error_;  // "" or why there are none
};

testing::TempDir* McapConformance::written_ = nullptr;
std::string* McapConformance::read_dir_ = nullptr;
std::string* McapConformance::setup_error_ = nullptr;

// Reads every file of the case folder `case_name` both ways; counts into
// *files_read, *streamed (right in file order), *in_log_time (right in
// log-time order, streaming and through the indexes where used) and
// *indexed (read through the indexes, and right).
void CheckCase(const std::string& fixture_dir, const std::string& read_dir,
               const std::string& case_name, int* files_read, int* streamed, int* in_log_time,
               int* indexed) {
  const std::vector<std::string> files = McapFilesOf(read_dir + "/" + case_name);
  ASSERT_EQ(files.size(), McapFilesOf(fixture_dir + "/" + case_name).size());
  ASSERT_FALSE(files.empty()) << fixture_dir << "/" << case_name << " holds no .mcap";
  for (const std::string& file : files) {
    SCOPED_TRACE(file);
    ++*files_read;
    std::vector<ConformanceMessage> in_file_order;
    const std::string json = fixture_dir + "/" + case_name + "/" +
                             fs::path(file).replace_extension(".json").filename().string();
    const std::string json_error = ExpectedMessages(json, &in_file_order);
    ASSERT_EQ(json_error, "");
    std::vector<ConformanceMessage> in_log_time_order = in_file_order;
    std::stable_sort(in_log_time_order.begin(), in_log_time_order.end(),
                     [](const ConformanceMessage& a, const ConformanceMessage& b) {
                       return a.log_time < b.log_time;
                     });

    // The streaming read: the data section scanned, messages in file order.
    std::vector<ConformanceMessage> messages;
    bool used_summary = true;
    EXPECT_EQ(ReadWith(file, McapReader::SummaryUse::kNever, McapReader::Order::kFile,
                       &used_summary, &messages),
              "");
    EXPECT_FALSE(used_summary);
    EXPECT_EQ(messages, in_file_order) << "streaming, in file order";
    *streamed += messages == in_file_order;
    // The same read in log-time order (ReadMessages' order).
    messages.clear();
    EXPECT_EQ(ReadWith(file, McapReader::SummaryUse::kNever, McapReader::Order::kLogTime,
                       &used_summary, &messages),
              "");
    EXPECT_EQ(messages, in_log_time_order) << "streaming, in log-time order";
    bool right_in_log_time = messages == in_log_time_order;
    if (HasOption(file, "chx") && HasOption(file, "mx")) {
      // Through the chunk and message indexes of the summary. The reader
      // uses them when the summary also repeats the channels (rch); without
      // them it must open every chunk anyway, and scans.
      messages.clear();
      EXPECT_EQ(ReadWith(file, McapReader::SummaryUse::kIfUsable, McapReader::Order::kLogTime,
                         &used_summary, &messages),
                "");
      EXPECT_EQ(used_summary, HasOption(file, "rch")) << "whether the indexes were used";
      EXPECT_EQ(messages, in_log_time_order) << "through the indexes, in log-time order";
      right_in_log_time = right_in_log_time && messages == in_log_time_order;
      *indexed += used_summary && messages == in_log_time_order;
    }
    *in_log_time += right_in_log_time;
  }
}

TEST_F(McapConformance, EveryFileReadsAsItsJsonSays) {
  const std::string dir = ConformanceDir();
  if (dir.empty()) {
    GTEST_SKIP() << "no ../shared/fixtures/bags/mcap_conformance/ next to the repository";
  }
  ASSERT_EQ(*setup_error_, "");
  int files = 0, streamed = 0, in_log_time = 0, indexed = 0;
  for (const char* case_name : {"NoData", "OneAttachment", "OneMessage", "OneMetadata",
                                "OneSchemalessMessage", "TenMessages"}) {
    CheckCase(dir, *read_dir_, case_name, &files, &streamed, &in_log_time, &indexed);
  }
  EXPECT_EQ(files, 416);
  EXPECT_EQ(streamed, files);
  EXPECT_EQ(in_log_time, files);
  EXPECT_EQ(indexed, 40);  // the files with chx, mx and rch
  std::cout << "MCAP conformance: " << streamed << "/" << files
            << " files right streaming in file order, " << in_log_time << "/" << files
            << " right in log-time order, " << indexed
            << " of them also read through their indexes\n";
}

// The suite is whole: 416 .mcap files, each with its .json.
TEST(McapConformanceSuite, HoldsEveryFileWithItsJson) {
  const std::string dir = ConformanceDir();
  if (dir.empty()) {
    GTEST_SKIP() << "no ../shared/fixtures/bags/mcap_conformance/ next to the repository";
  }
  int mcap_files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (entry.path().extension() != ".mcap") continue;
    ++mcap_files;
    EXPECT_TRUE(fs::exists(fs::path(entry.path()).replace_extension(".json"))) << entry.path();
  }
  EXPECT_EQ(mcap_files, 416);
}

}  // namespace
}  // namespace tiltcal::mcap
